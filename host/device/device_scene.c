/* device_scene.c — a compiled scene (compiled_scene.h) onto one device: one buffer per
 * entry of VBCL_SCENE_BUFFERS, and the frame constants' buffer. */
#include "device_scene.h"

#include <stdio.h>
#include <string.h>

/* The host's packed top cells (grid.h) are the kernels' VbGridCell array. */
VBCL_STATIC_ASSERT(GRID_SUB_BITS == VBCL_GRID_SUB_BITS, grid_sub_bits);
VBCL_STATIC_ASSERT(sizeof(VbGridCell) == 2 * sizeof(uint32_t), grid_cell_words);

/* Whether the largest of cs's buffers fits in one allocation on dev; else 0 with a message. */
static int fits_device(const CompiledScene *cs, const Scene *s, const VbDevice *dev, char *err,
                       size_t errlen)
{
    const Grid *g = &cs->grid;
    if (sizeof(VbTriangle) * cs->ntris <= dev->max_alloc &&
        sizeof(VbLeafQuad) * cs->nquads <= dev->max_alloc &&
        sizeof(uint32_t) * ((size_t)g->nleaves + 1) <= dev->max_alloc)
        return 1;
    snprintf(err, errlen,
             "%s: the scene (%u triangles, %u grid references in %u leaves) does not fit in one "
             "allocation on %s (%.0f MiB at most)",
             s->path, cs->ntris, g->nleaf_refs, g->nleaves, dev->name,
             (double)dev->max_alloc / 1048576.0);
    return 0;
}

int scene_buffers_upload(SceneBuffers *b, VbDevice *dev, const CompiledScene *cs, const Scene *s,
                         char *err, size_t errlen)
{
    memset(b, 0, sizeof *b);
    if (!fits_device(cs, s, dev, err, errlen)) return 2;
    const Grid *g = &cs->grid;
    const CamTiles *t = &cs->cam;
    size_t nstart = t->nx ? (size_t)t->nx * (size_t)t->ny + 1 : 0;
    const cl_mem_flags ro = CL_MEM_READ_ONLY;
    b->frame = clu_buffer(dev, NULL, sizeof cs->frame, ro);
    b->tris = clu_buffer(dev, cs->tris, sizeof(VbTriangle) * cs->ntris, ro);
    b->normals =
        clu_buffer(dev, cs->normals, cs->normals ? sizeof(VbTriNormals) * cs->ntris : 0, ro);
    b->grid_cells = clu_buffer(dev, g->cells, sizeof(VbGridCell) * g->ncells, ro);
    b->leaf_start = clu_buffer(dev, cs->leaf_start, sizeof(uint32_t) * (g->nleaves + 1u), ro);
    b->leaf_quads = clu_buffer(dev, cs->quads, sizeof(VbLeafQuad) * cs->nquads, ro);
    b->materials = clu_buffer(dev, cs->materials, sizeof(VbMaterial) * (size_t)cs->nmaterials, ro);
    b->objects = clu_buffer(dev, cs->objects, sizeof(VbObject) * cs->nobjects, ro);
    b->lights = clu_buffer(dev, s->lights, sizeof(VbLight) * (size_t)s->nlights, ro);
    b->patterns = clu_buffer(dev, cs->patterns, sizeof(VbPattern) * (size_t)cs->npatterns, ro);
    b->texels = clu_buffer(dev, cs->texels, sizeof(float) * 4 * cs->ntexels, ro);
    b->cam_start = clu_buffer(dev, t->start, sizeof(uint32_t) * nstart, ro);
    b->cam_quads = clu_buffer(dev, t->quads, sizeof(VbLeafQuad) * t->nquads, ro);
    b->cam_near = clu_buffer(dev, t->near, sizeof(float) * t->nquads, ro);
#define SCENE_BUFFER_MADE(space, type, name, field) &&b->field
    if (1 VBCL_SCENE_BUFFERS(SCENE_BUFFER_MADE)) return 0;
#undef SCENE_BUFFER_MADE
    if (clu_error_out_of_memory())
        snprintf(err, errlen,
                 "%s: out of memory for the scene's buffers on %s (%.0f MiB of triangles, grid "
                 "and camera tiles); fewer triangles or a coarser grid (render.grid) take less",
                 s->path, dev->name,
                 (double)(sizeof(VbTriangle) * cs->ntris + sizeof(VbLeafQuad) * cs->nquads +
                          sizeof(VbGridCell) * g->ncells + sizeof(VbLeafQuad) * t->nquads) /
                     1048576.0);
    else
        snprintf(err, errlen, "%s: %s", dev->name, clu_error());
    return 1;
}

int scene_buffers_set_args(const SceneBuffers *b, cl_kernel k)
{
#define SCENE_BUFFER_PTR(space, type, name, field) &b->field,
    const cl_mem *m[SCENE_BUFFER_ARGS] = {VBCL_SCENE_BUFFERS(SCENE_BUFFER_PTR)};
    for (cl_uint i = 0; i < SCENE_BUFFER_ARGS; i++)
        if (clu_set_arg(k, i, sizeof(cl_mem), m[i])) return -1;
    return 0;
}

void scene_buffers_release(SceneBuffers *b)
{
    cl_mem *m[SCENE_BUFFER_ARGS] = {VBCL_SCENE_BUFFERS(SCENE_BUFFER_PTR)};
#undef SCENE_BUFFER_PTR
    for (int i = 0; i < SCENE_BUFFER_ARGS; i++)
        if (*m[i]) CL_WARN(clReleaseMemObject(*m[i]));
    memset(b, 0, sizeof *b);
}
