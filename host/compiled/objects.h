/* objects.h — the object analysis: the kernels' VbObject records of a scene (types.h), each
 * with the bounds and the properties of its geometry that the shadow cone test, the ray
 * trees' object sets and the solid cores rely on (docs/architecture.md, "Shadow feelers"). */
#ifndef VBCL_OBJECTS_H
#define VBCL_OBJECTS_H

#include <stddef.h>

#include "scene.h"

/* The records of s: its objects in order, then the parts of their textures (each object's
 * first_elem .. first_elem + nelems - 1), *count records in all; quad_tri and quad_tex are
 * left for the packer (compiled_scene.c). NULL: out of memory. */
VbObject *objects_make(const Scene *s, size_t *count);

#endif
