#line 2 "scene.cl"
/* scene.cl — the scene as device functions see it: one bundle of the frame's buffers,
 * passed by pointer instead of eight arguments to every function. */

typedef struct DevScene {
    __constant const VbFrame *f;
    __global const VbTriangle *tris;
    __global const VbTriNormals *normals;
    __global const uint *cell_start;
    __global const uint *cell_tris;
    __global const VbMaterial *materials;
    __global const VbObject *objects;
    __global const VbLight *lights;
} DevScene;

/* Closest hit of (org, dir) within tmax, through the grid. */
VB_INLINE VbHit scene_trace_closest(const DevScene *sc, float3 org, float3 dir, float tmax,
                                    TraceCount *tc)
{
    return grid_trace_closest(&sc->f->grid, sc->tris, sc->cell_start, sc->cell_tris, org, dir, tmax,
                              tc);
}

/* Whether anything lies on (org, dir) before tmax. */
VB_INLINE int scene_trace_any(const DevScene *sc, float3 org, float3 dir, float tmax,
                              TraceCount *tc)
{
    return grid_trace_any(&sc->f->grid, sc->tris, sc->cell_start, sc->cell_tris, org, dir, tmax,
                          tc);
}

/* Material of an opaque-scene triangle: its object's own material. */
VB_INLINE uint scene_tri_material(const DevScene *sc, int tri)
{
    return sc->objects[tri_tag(sc->tris, tri) & ~VBCL_TAG_TEXTURE].material;
}
