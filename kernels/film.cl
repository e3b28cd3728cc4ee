#line 2 "film.cl"
/* film.cl — the anti-aliasing kernels that trace nothing (thesis 4.1.2): the contrast test
 * over the film and the quadtrees, the list of pixels to test again, storing a split's
 * samples, and the reconstruction of supersampled and refined pixels. A small program of
 * its own, the same for every scene (the kernels that generate anti-aliasing's rays are in
 * render.cl, beside the camera's). */
#ifndef VBCL_FILM_CL
#define VBCL_FILM_CL

#include "aa.cl"

/* radiance -> film: uniform supersampling, each pixel of a batch the mean of its side^2
 * samples (a box window over its own subpixels, thesis figure 4.4). */
__kernel void aa_reconstruct(__constant const VbAaPass *aa, __global const float *radiance,
                             __global float *film)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    uint n = (uint)(aa->side * aa->side);
    float4 sum = (float4)(0.0f);
    for (uint k = 0; k < n; k++) sum += vload4(j * n + k, radiance);
    vstore4(sum * (1.0f / (float)n), aa->first + j, film);
}

/* film, slots, trees, split -> marks, counts: the contrast test (aa_contrast_pixel) over the
 * whole image: in round 0 every pixel, later those whose neighbourhood was split last round
 * (aa_pixel_dirty). split holds two rounds' blocks, the last round's read and this round's
 * cleared. */
__kernel void aa_contrast_mark(__constant const VbAaPass *aa, __global const float *film,
                               __global const int *slots, __global const uchar *levels,
                               __global const float *values, __global uint2 *marks,
                               __global uint *counts, __global uint *split)
{
    int p = get_global_id(0), npix = aa->width * aa->height;
    AaTree tree = {levels, values, aa->tree_cap};
    if (p >= npix) return;
    /* this round's splits are recorded in the other half of split[] */
    __global const uint *last = split + (aa->round + 1) % 2 * npix;
    split[aa->round % 2 * npix + p] = 0u;
    if (!aa_pixel_dirty(aa, last, p % aa->width, p / aa->width)) return;
    aa_contrast_pixel(aa, film, slots, tree, marks, counts, last, p);
}

/* film, slots, trees, split, list -> marks, counts: the contrast test (aa_contrast_pixel) of
 * the aa->entries pixels listed, those in or next to a pixel split last round
 * (aa_dirty_list): the other pixels' leaves and their neighbours are as they were when they
 * last passed. The host clears this round's half of split. */
__kernel void aa_contrast_list(__constant const VbAaPass *aa, __global const float *film,
                               __global const int *slots, __global const uchar *levels,
                               __global const float *values, __global uint2 *marks,
                               __global uint *counts, __global const uint *split,
                               __global const uint *list)
{
    uint j = get_global_id(0);
    AaTree tree = {levels, values, aa->tree_cap};
    if (j >= aa->entries) return;
    __global const uint *last = split + (aa->round + 1) % 2 * aa->width * aa->height;
    aa_contrast_pixel(aa, film, slots, tree, marks, counts, last, (int)list[j]);
}

/* marks, tags -> list, count: the pixels the next round tests, each once: the pixel of each
 * of the aa->entries marks split in round aa->round and its 8 neighbours. tags[q] holds the
 * round after the last one whose list q joined (0: none). */
__kernel void aa_dirty_list(__constant const VbAaPass *aa, __global const uint2 *marks,
                            __global uint *tags, __global uint *list, __global uint *count)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    int p = (int)marks[j].x, x = p % aa->width, y = p / aa->width;
    uint tag = (uint)aa->round + 1u;
    for (int qy = max(y - 1, 0); qy <= min(y + 1, aa->height - 1); qy++)
        for (int qx = max(x - 1, 0); qx <= min(x + 1, aa->width - 1); qx++) {
            int q = qy * aa->width + qx;
            if (atomic_xchg(&tags[q], tag) != tag) list[atomic_inc(count)] = (uint)q;
        }
}

/* radiance, marks -> levels, values, slots, slot_pixels, split: each marked node of a
 * batch becomes four leaves one level deeper: the child holding the node's sample keeps its
 * value, the other three take the new samples. A pixel split for the first time gets a tree
 * slot (counts[VBCL_AA_MAX_LEVEL + 1] counts the slots; the host made room for them); each
 * split node's blocks (aa_node_blocks) are ORed into its pixel's mask in this round's half
 * of split. */
__kernel void aa_split_store(__constant const VbAaPass *aa, __global const uint2 *marks,
                             __global const float *radiance, __global const float *film,
                             __global int *slots, __global int *slot_pixels, __global uchar *levels,
                             __global float *values, __global uint *counts, __global uint *split)
{
    uint j = get_global_id(0);
    if (j >= aa->entries) return;
    aa_split_node(aa, marks[aa->first + j], j, radiance, film, slots, slot_pixels, levels, values,
                  counts, split);
}

/* levels, values, slot_pixels, slots -> film, info: each refined pixel becomes the mean of
 * its finest cells (a box window over the pixel's own footprint, figure 4.4), each cell the
 * value of the sample nearest to it among the pixel's own and its refined neighbours' near
 * it (aa_nearest_weights; from[s] is the tree slot of the pixel at source s) or, with
 * aa->reconstruct 1, of the leaf covering it (the area-weighted mean of the leaves, the
 * thesis's); info its deepest level | leaf count << 8. */
__kernel void aa_resolve(__constant const VbAaPass *aa, __global const int *slot_pixels,
                         __global const uchar *levels, __global const float *values,
                         __global float *film, __global int *info, __global const int *slots)
{
    uint slot = get_global_id(0);
    if (slot >= aa->entries) return;
    int p = slot_pixels[slot], deepest = 0, nleaves = 0;
    AaTree tree = {levels, values, aa->tree_cap};
    float3 sum = aa_resolve_pixel(aa, tree, slots, (int)slot, p, &deepest, &nleaves);
    vstore4((float4)(sum * (1.0f / (float)VBCL_AA_CELLS), 1.0f), p, film);
    info[p] = deepest | nleaves << 8;
}

#endif
