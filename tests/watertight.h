/* watertight.h — rays aimed at the shared edges and vertices of closed meshes, traced on
 * the device, counting leaks and self-intersections (tests/test_stability.c and the
 * stress program tests/stress/stress_main.c share it). */
#ifndef VBCL_WATERTIGHT_H
#define VBCL_WATERTIGHT_H

#include <stddef.h>

#include "clu.h"

/* Counts over one or more runs; watertight_run adds to them. */
typedef struct WtStats {
    unsigned long long aimed;        /* rays aimed at an edge or vertex point (the renderer's
                                        scene_intersect_closest) */
    unsigned long long camera_aimed; /* of those: from the camera's eye, through the image (its
                                       camera tiles, camera_trace_closest) */
    unsigned long long leaks;        /* of those: no hit, a first hit past the aimed point, or
                                        (from outside) a first hit on a back face */
    unsigned long long brute_aimed;  /* the same rays traced by probe_intersect_brute */
    unsigned long long brute_leaks;
    unsigned long long offset_rays; /* rays leaving hit points from the offset origin */
    unsigned long long self_hits;   /* of those: hits on the own triangle, or on a neighbour
                                       whose plane the ray does not cross in double precision */
    unsigned long long escapes;     /* of those leaving into the inside: first hits within
                                       1e-3 * size on the wrong side of a neighbour whose plane
                                       the ray does cross (within rounding): the offset origin
                                       lies in the other medium */
    unsigned long long escapes_out; /* the same for rays leaving into the outside (shadow
                                       feelers), where any hit leaving a convex mesh counts */
    /* of escapes + escapes_out: those whose offset, from the hit point to the origin, crosses
     * the plane of no triangle around the start triangle's corners, with neither the hit
     * point nor the origin within the point's rounding of one: not the offset's doing */
    unsigned long long escapes_unexplained;
    /* offset rays whose first hit is on a triangle whose plane they run along, to within 4
     * units in the last place of their direction: not checked */
    unsigned long long grazing;
    /* offset rays whose first hit is on another piece of the mesh (a texture's element,
     * which may overlap the start one): not checked */
    unsigned long long other_piece;
    unsigned long long skipped; /* targets with no clean entering direction */
    double seconds;             /* wall time of the device traces, transfers included */
} WtStats;

/* A closed shape to fire rays at: the JSON of its shape keys (without the material), and
 * whether it is convex (a ray leaving it outward may hit nothing). */
typedef struct WtShape {
    const char *name;
    const char *json;
    int convex;
    double thin; /* its thinnest extent at scale 1 */
} WtShape;

/* The shapes every run covers: icosphere levels, surfaces of revolution, prisms, boxes. */
extern const WtShape watertight_shapes[];
extern const int watertight_nshapes;

/* Writes a scene holding one object (object: the JSON of its shape keys, without the
 * material, e.g. "\"shape\": \"sphere\", \"level\": 3") scaled by `scale` and translated
 * by offset, seen from 10 * scale along z, into out. look_origin: the camera looks at
 * (0, 0, 0) from 10 * scale along z instead, so that the scene's frame (scene_frame_pick)
 * stays at the origin and the object keeps the magnitude of its offset: the kernels' own
 * arithmetic far from the origin. */
void watertight_scene_json(const char *object, double scale, const double offset[3],
                           int look_origin, char *out, size_t n);

/* The cases the stability suite and the stress program run: every shape at each scale, at
 * the origin and moved 76 sizes away (both in the scene's frame, which brings them to the
 * origin and to unit size), and at scale 1 moved 1e3, 1e4 and 1e5 away from a camera that
 * looks at the origin (the frame leaves them there). */
#define WT_NCASES 13
typedef struct WtCase {
    double scale;
    double offset[3];
    int look_origin;
    const char *label; /* "", "moved" or "far" */
} WtCase;
void watertight_case(int k, WtCase *c);

/* Whether the shape keeps its form in floats in case c: its thinnest extent spans at least
 * 64 units in the last place of the coordinates there (a flat box 1e4 from the origin
 * collapses into degenerate and crossing triangles, which no ray test can hold to). */
int watertight_case_fits(const WtShape *sh, const WtCase *c);

/* Loads the scene at scene_path (its mesh must be closed), prepares it on d with the test
 * kernels and fires `targets` aimed points' worth of rays at it: per target one ray from
 * far outside and one from just inside, each crossing the surface at the point, one from the
 * camera's eye where the eye lies outside the mesh's bounds and the point in the image (a
 * camera ray, traced through the camera tiles), and per
 * hit two rays leaving it from the offset origin (along the normal and in a random
 * direction, back into the side the ray came from). The self-hit distance is 1e-3 times
 * the mesh's bounding-box diagonal; convex: the mesh is convex, so an outward ray must hit
 * nothing. brute_every > 0 also traces the rays of every brute_every-th target by brute
 * force. Adds to st. Returns 0, or -1 with a message in err. */
int watertight_run(VbDevice *d, const char *scene_path, int convex, long targets, unsigned seed,
                   int brute_every, WtStats *st, char *err, size_t errlen);

#endif
