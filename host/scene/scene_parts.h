/* scene_parts.h — internal to host/scene/: the stages of scene_load_text, one file each
 * (scene_environment.c, scene_materials.c, scene_shapes.c, scene_texture.c, scene_objects.c,
 * scene_animation.c). Each reads one part of the document into the Scene and reports
 * through the Ctx (scene_json.h). Not included outside host/scene/. */
#ifndef VBCL_SCENE_PARTS_H
#define VBCL_SCENE_PARTS_H

#include "scene.h"
#include "scene_json.h"

/* image.environment (img: the image object), its file read and checked, into s->env
 * (scene_environment.c). */
int scene_load_environment(Ctx *c, const cJSON *img, Scene *s);

/* materials[]: every material, its pattern and dispersion (scene_materials.c). */
int scene_load_materials(Ctx *c, const cJSON *j, Scene *s);
/* The index of the material called name, or -1. */
int scene_find_material(const Scene *s, const char *name);
/* Without render.bands, a scene whose dispersive materials all use the thesis model
 * renders with the thesis's per-channel rays. */
void scene_default_band_layout(const cJSON *render, Scene *s);

/* obj.transform as an object-to-world matrix: scale, rotate about x, y, z, translate
 * (identity when absent) (scene_shapes.c). */
int scene_load_transform(Ctx *c, const cJSON *obj, const char *path, mat4 *xf);
/* The same into s's frame (scene_frame_pick): the translation subtracted from the frame's
 * origin in double, as written, so that an object far from (0, 0, 0) keeps its digits. */
int scene_load_transform_framed(Ctx *c, const cJSON *obj, const char *path, const Scene *s,
                                mat4 *xf);
/* A sphere's radius and centre (objects[i] o, checked by its shape) put into xf, its centre
 * as written, in double, where s's frame is not the file's own (else its mesh has them). */
void scene_sphere_transform(const cJSON *o, const Scene *s, mat4 *xf);
/* The point obj[key] (checked as json_get_vec3 does; def when absent) in s's frame, from the
 * numbers as written (double). */
int scene_get_point(Ctx *c, const cJSON *obj, const char *path, const char *key, const float *def,
                    const Scene *s, vec3 *out);
/* Tessellates one object's shape into m (object space). */
int scene_load_shape(Ctx *c, const cJSON *o, const char *p, const char *shape, const Scene *s,
                     Mesh *m);
/* Refuses a scene whose shapes make more than SCENE_MAX_TRIANGLES before any is built. */
int scene_count_triangles(Ctx *c, const cJSON *j);

/* objects[i].texture into tex, mapped onto the host's box [host_lo, host_hi] in the
 * object's own space; *material is the texture's material (scene_texture.c). */
int scene_load_texture(Ctx *c, const cJSON *t, const char *p, const Scene *s, vec3 host_lo,
                       vec3 host_hi, Mesh *tex, int *material);

/* objects[]: every object and its texture into the scene mesh, then the check that hosts
 * do not overlap (scene_objects.c). */
int scene_load_objects(Ctx *c, const cJSON *j, Scene *s);
/* Notes in s->warning (the first only) when triangles of the texture tex lie in faces of
 * its host (both in the object's own space) that are planes of the host's bounding box: a
 * ray meets both at one distance and such a face renders as speckle. p: the JSON path of
 * the texture. */
void scene_texture_check_faces(Ctx *c, const char *p, const Mesh *host, const Mesh *tex, Scene *s);

/* Applies root.animation for frame `frame` (-1: checks the tracks, changes nothing) and
 * returns the frame count in *frames (scene_animation.c). */
int scene_anim_apply(Ctx *c, cJSON *root, int frame, int *frames);

#endif
