#line 2 "objects.cl"
/* objects.cl — the object sets of rays and feelers: which objects' and texture parts'
 * triangles a cone of rays (a point's feelers toward a light, a ray of a ray tree) can meet,
 * from the bounds and properties of the object analysis (VbObject, host/compiled/objects.c):
 * the cone test against a record's box and plane, the parts behind a host's planes, and the
 * set of a ray-tree ray (ray_objects). The feelers' sets are made in light.cl
 * (light_cone_objects) from the same tests. */
#ifndef VBCL_OBJECTS_CL
#define VBCL_OBJECTS_CL

#include "scene.cl"

/* Whether the cone from o around the unit axis, of half-angle theta (tan_t = tan theta), up
 * to distance d, can meet the box [lo, hi]: the cone is cut into 4 pieces along the axis,
 * and piece i, between distances d i / 4 and d (i + 1) / 4, lies within d (i + 1) / 4 tan_t
 * of the axis, so it can meet the box only if that stretch of the axis meets the box widened
 * by this radius and the margin m (slab test). A cone of no width (a ray, a point light's
 * feelers) is one piece: its four would be the same slab test on stretches that cover the
 * one from end to end. Conservative: true where unsure. */
VB_INLINE int light_cone_meets_box(float3 o, float3 axis, float d, float tan_t, float3 lo,
                                   float3 hi, float m)
{
    float3 inv = 1.0f / axis;
    int3 flat = isless(fabs(axis), (float3)(1e-12f));
    int pieces = tan_t > 0.0f ? 4 : 1;
    float step = tan_t > 0.0f ? 0.25f : 1.0f;
    for (int i = 0; i < pieces; i++) {
        float t0 = d * step * (float)i, t1 = d * step * (float)(i + 1);
        float rad = t1 * tan_t + m;
        float3 a = (lo - rad - o) * inv, b = (hi + rad - o) * inv;
        float3 tn = fmin(a, b), tf = fmax(a, b);
        /* an axis the direction runs along: the stretch lies inside its slab or outside */
        int3 inside = isgreaterequal(o, lo - rad) & islessequal(o, hi + rad);
        tn = select(tn, select((float3)(INFINITY), (float3)(-INFINITY), inside), flat);
        tf = select(tf, select((float3)(-INFINITY), (float3)(INFINITY), inside), flat);
        float enter = fmax(fmax(tn.x, tn.y), fmax(tn.z, t0 - m));
        float leave = fmin(fmin(tf.x, tf.y), fmin(tf.z, t1 + m));
        if (enter <= leave) return 1;
    }
    return 0;
}

/* The cone of a point's feelers toward a light (light_cone_objects): from o around the
 * unit axis, half-angle theta (sin_t, cos_t), to the light's centre c at distance d, the
 * light's radius r; reach sizes the plane test's margin. */
typedef struct LightCone {
    float3 o, axis, c;
    float d, r, sin_t, cos_t, reach;
} LightCone;

/* Whether a feeler in cone k can meet a triangle that record ob bounds (an object with its
 * texture, or a part of a texture): its bounding sphere meets the cone within its length
 * (the sphere's centre no farther from the cone's surface than its radius: perp cos theta
 * - along sin theta <= R, a lower bound of the distance, so the test is conservative), its
 * box does (light_cone_meets_box), and, for a planar one, its plane separates the origin
 * from some point of the light sphere. */
VB_INLINE int light_cone_meets(const LightCone *k, __global const VbObject *ob)
{
    float4 b = vload4(0, ob->bound);
    if (b.w < 0.0f) return 0;
    float3 v = b.xyz - k->o;
    float along = dot(v, k->axis);
    float perp = length(v - along * k->axis);
    float m = b.w + 1e-5f * (k->d + fabs(along) + perp + b.w);
    if (along < -m || along > k->d + m) return 0;
    if (perp * k->cos_t - along * k->sin_t > m) return 0;
    if (!light_cone_meets_box(k->o, k->axis, k->d, k->sin_t / fmax(k->cos_t, 1e-6f),
                              vload3(0, ob->lo), vload3(0, ob->hi), m - b.w))
        return 0;
    if (ob->flags & VBCL_OBJECT_PLANAR) {
        float4 pl = vload4(0, ob->plane);
        float e = ob->plane_eps + 1e-6f * k->reach;
        float so = dot(pl.xyz, k->o) - pl.w, sl = dot(pl.xyz, k->c) - pl.w;
        if ((so > e && sl - k->r > e) || (so < -e && sl + k->r < -e)) return 0;
    }
    return 1;
}

/* The bit of VbObject.ahead that a ray or feeler leaving host ob through the front of its own
 * triangle tri tests: a part without it lies wholly behind that triangle's plane. */
VB_INLINE uint part_ahead_bit(__global const VbObject *ob, int tri)
{
    return ob->ntris <= (uint)VBCL_AHEAD_BITS ? 1u << ((uint)tri - ob->first_tri) : 0xffffffffu;
}

/* Adds the parts of record ob's texture that a ray of cone k meets (light_cone_meets) to the set:
 * a small one's triangles, a bigger one as big; where ahead is not 0 (part_ahead_bit: the ray
 * leaves ob through the front of one of its own triangles), only parts that may reach ahead of
 * that triangle's plane. 0 where the set overflows. */
VB_INLINE int ray_parts(const DevScene *scn, const LightCone *k, __global const VbObject *ob,
                        uint ahead, ObjectSet *os)
{
    for (uint e = ob->first_elem; e < ob->first_elem + ob->nelems; e++) {
        __global const VbObject *el = scn->objects + e;
        if ((ahead && !(el->ahead & ahead)) || !light_cone_meets(k, el)) continue;
        if (el->ntris <= VBCL_OBJECT_SET_MAX_TRIS / 2 ? !object_set_add(os, el->quad_tri, el->ntris)
                                                      : !object_set_big(os, e))
            return 0;
    }
    return 1;
}

/* The object a ray from org along the unit axis leaves behind, starting on triangle tri
 * (-1: none): that triangle's object where the ray moves away from the triangle's plane,
 * on the side it starts on (a reflection about a smooth normal can turn back in), and the
 * triangle is the object's own, not a texture element's (whose surface is not its host's,
 * as in shade_point_make); else -1. *front: the ray leaves to the triangle's outer side. */
VB_INLINE int ray_start_object(const DevScene *scn, float3 org, float3 axis, int tri, int *front)
{
    *front = 0;
    if (tri < 0) return -1;
    float3 a = tri_vertex(scn->tris, tri, 0).xyz;
    float3 n = cross(tri_vertex(scn->tris, tri, 1).xyz - a, tri_vertex(scn->tris, tri, 2).xyz - a);
    float along = dot(n, axis), side = dot(n, org - a);
    uint tag = tri_tag(scn->tris, tri);
    if (!((along > 0.0f && side > 0.0f) || (along < 0.0f && side < 0.0f)) ||
        (tag & VBCL_TAG_TEXTURE))
        return -1;
    *front = along > 0.0f;
    return (int)(tag & ~VBCL_TAG_FLAGS);
}

/* The triangles that a ray of a ray tree, from org along dir, leaving triangle tri (-1:
 * none) and inside host `host` (VbMedium.host, -1: none), can meet (VBCL_FRAME_CONE_TEST,
 * as for feelers): those of the objects whose bounds the ray meets (light_cone_meets) between org
 * and where it leaves the grid's box, which holds every triangle. A small object's
 * triangles (and its texture's, where that has no parts and fits) are tested alone; a
 * bigger one is big: the grid is walked where the ray lies in its bounding sphere
 * (os->walk, object_set_span), its texture included. Parts of a texture are taken one by
 * one only where the object's own triangles are settled otherwise: a ray that goes on
 * counts every texture surface it crosses in its medium (medium_cross), also outside the
 * host, so no part it meets may be left out. A ray that moves away from its triangle's
 * plane, on the side it starts on, cannot meet a planar start object again, nor a convex
 * one it leaves to the outer side: their own triangles are left out (all of them lie
 * behind that plane), and so are the parts of a host's texture that lie behind it
 * (VbObject.ahead, part_ahead_bit). A ray inside a big convex host (VBCL_OBJECT_INNER), having
 * entered it through one of its own triangles, meets them again only on its way out, beyond the
 * host's inner sphere: the host is the set's shell, walked only there; and where every way
 * out of the host is an interface (its material and its texture's both differ from the
 * air's) the search ends where the ray leaves the host, since medium_trace stops at the
 * first interface. Any other ray inside a host walks the grid. Returns the distance along
 * dir beyond which nothing need be searched (with a margin; 0 where the ray misses the box,
 * the set then empty), INFINITY with os->n = -1 (the grid) where the test is off or the set
 * overflows; medium_trace within that distance through the set follows the ray as through
 * the grid. */
VB_INLINE float ray_objects(const DevScene *scn, float3 org, float3 dir, int tri, int host,
                            ObjectSet *os)
{
    os->n = -1;
    os->sole = -1;
    os->shell = -1;
    if (!(scn->f->flags & VBCL_FRAME_CONE_TEST)) return INFINITY;
    float len = length(dir);
    float3 axis = dir / len;
    float2 box = grid_box_span(&scn->f->grid, org, (float3)(1.0f) / axis);
    float m = 1e-4f * (fabs(box.y) + vb_max3(fabs(org)) +
                       vb_max3(vb_cload3(scn->f->grid.hi) - vb_cload3(scn->f->grid.lo)));
    int front;
    int object = ray_start_object(scn, org, axis, tri, &front);
    /* inside a host, only a big convex one's own triangles are settled without the grid
     * (its shell; a small host's few are no cheaper in a set, measured on A.4), and only for
     * a ray that enters it through one of them (offset inward: surely inside it; one from a
     * texture's surface near the host's may lie a rounding outside) */
    if (host >= 0 && (object != host || front || !(scn->objects[host].flags & VBCL_OBJECT_INNER)))
        return INFINITY;
    os->n = 0;
    os->tris = 0u;
    os->nbig = 0;
    os->walk = 0;
    if (!(box.x <= box.y + m && box.y >= -m)) return 0.0f; /* it misses the box */
    LightCone k;
    k.o = org;
    k.axis = axis;
    k.d = fmax(box.y, 0.0f) + m;
    if (host >= 0) {
        /* a ray inside a convex host whose every way out is an interface ends its search
         * where it leaves the host (medium_trace stops at the first interface) */
        __global const VbObject *ho = scn->objects + host;
        uint air = scn->f->air_material;
        if ((ho->flags & VBCL_OBJECT_HULL) && ho->material != air && ho->tex_material != air) {
            float2 st = object_hull_stretch(scn, ho, org, axis, k.d, m);
            if (st.x <= st.y) k.d = fmin(k.d, fmax(st.y, 0.0f) + m);
        }
    }
    k.c = org + k.d * axis;
    k.r = 0.0f;
    k.sin_t = 0.0f;
    k.cos_t = 1.0f;
    k.reach = vb_max3(fabs(k.o)) + vb_max3(fabs(k.c));
    for (uint i = 0; i < scn->f->nobjects; i++) {
        __global const VbObject *ob = scn->objects + i;
        uint flags = ob->flags;
        if ((int)i == host) { /* inside it: its own triangles as a shell */
            os->shell = (int)i;
            if (ob->nelems > 0u ? !ray_parts(scn, &k, ob, 0u, os)
                                : ob->ntex > 0u && (ob->quad_tex == VBCL_NO_QUADS ||
                                                    !object_set_add(os, ob->quad_tex, ob->ntex))) {
                os->n = -1; /* a texture too big for the set and without parts: the grid */
                return INFINITY;
            }
            continue;
        }
        int own =
            (int)i == object && ((flags & VBCL_OBJECT_PLANAR) ||
                                 ((flags & (VBCL_OBJECT_CONVEX | VBCL_OBJECT_HULL)) && front));
        if (own && ob->ntex == 0u) continue;
        if (!light_cone_meets(&k, ob)) continue;
        if (own && ob->nelems > 0u) { /* its own triangles left behind: the parts */
            if (!ray_parts(scn, &k, ob, front ? part_ahead_bit(ob, tri) : 0u, os)) return INFINITY;
            continue;
        }
        int small = !own && ob->ntris <= VBCL_OBJECT_SET_MAX_TRIS / 2 &&
                    (ob->ntex == 0u || ob->quad_tex != VBCL_NO_QUADS);
        if (small ? !object_set_add(os, ob->quad_tri, ob->ntris) ||
                        !object_set_add(os, ob->quad_tex, ob->ntex)
                  : !object_set_big(os, i))
            return INFINITY;
    }
    os->walk = os->nbig > 0 || os->shell >= 0;
    return k.d / len;
}

#endif
