/* render.c — the host side of a frame: scene to device buffers, the uniform grid, the
 * kernel program, and the tile loop that enqueues camera rays, closest hits and shading. */
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "aa.h"
#include "dispersion.h"
#include "kernel_features.h"
#include "texgen.h"

/* Fills the camera of the frame from the scene's eye, look_at, up and fov. */
static void frame_camera(const Scene *s, VbCamera *c)
{
    vec3 fwd = v3_norm(v3_sub(s->look_at, s->eye));
    vec3 right = v3_norm(v3_cross(fwd, s->up));
    vec3 up = v3_cross(right, fwd);
    float th = tanf(s->fov * 0.5f * (float)(M_PI / 180.0));
    float aspect = (float)s->width / (float)s->height;
    right = v3_scale(right, th * aspect);
    up = v3_scale(up, th);
    float *dst[4] = {c->eye, c->forward, c->right, c->up};
    vec3 src[4] = {s->eye, fwd, right, up};
    for (int i = 0; i < 4; i++) {
        dst[i][0] = src[i].x;
        dst[i][1] = src[i].y;
        dst[i][2] = src[i].z;
        dst[i][3] = 0.0f;
    }
}

static void frame_grid(const Grid *g, VbGrid *out)
{
    memset(out, 0, sizeof *out);
    for (int i = 0; i < 3; i++) {
        out->lo[i] = g->lo[i];
        out->hi[i] = g->hi[i];
        out->cell[i] = g->cell[i];
        out->inv_cell[i] = 1.0f / g->cell[i];
        out->n[i] = g->n[i];
    }
}

/* Triangles as the kernels read them, the tag in the w of the first vertex. */
static VbTriangle *pack_triangles(const Scene *s)
{
    const Mesh *m = &s->mesh;
    VbTriangle *t = calloc(m->ntris, sizeof *t);
    if (!t) return NULL;
    for (uint32_t i = 0; i < m->ntris; i++) {
        float *dst[3] = {t[i].v0, t[i].v1, t[i].v2};
        for (int k = 0; k < 3; k++) {
            vec3 p = m->verts[m->tris[3 * i + k]];
            dst[k][0] = p.x;
            dst[k][1] = p.y;
            dst[k][2] = p.z;
        }
        memcpy(&t[i].v0[3], &s->tri_tag[i], sizeof(uint32_t));
    }
    return t;
}

static VbTriNormals *pack_normals(const Scene *s)
{
    const Mesh *m = &s->mesh;
    VbTriNormals *t = calloc(m->ntris ? m->ntris : 1, sizeof *t);
    if (!t || !m->normals) return t;
    for (uint32_t i = 0; i < m->ntris; i++) {
        float *dst[3] = {t[i].n0, t[i].n1, t[i].n2};
        for (int k = 0; k < 3; k++) {
            vec3 n = m->normals[m->tris[3 * i + k]];
            dst[k][0] = n.x;
            dst[k][1] = n.y;
            dst[k][2] = n.z;
        }
    }
    return t;
}

/* Builds the materials' surface patterns (Fourier coefficients, projected images) and
 * uploads them; sets mats[i].pattern. Returns 0, 2 (a pattern the scene cannot have, the
 * message naming the material) or 1 (device). */
static int upload_patterns(Renderer *r, const Scene *s, VbMaterial *mats, char *err, size_t errlen)
{
    VbPattern *pats = calloc((size_t)s->nmaterials + 1, sizeof *pats);
    float *texels = NULL;
    size_t ntexels = 0; /* in texels of 4 floats */
    int npats = 0, rc = 0;
    if (!pats) return 1;
    for (int i = 0; i < s->nmaterials && !rc; i++) {
        const ScenePattern *sp = &s->materials[i].pattern;
        if (!sp->kind) continue;
        VbPattern *pt = &pats[npats];
        char perr[512];
        pt->kind = sp->kind;
        for (int k = 0; k < 3; k++) {
            pt->origin[k] = sp->origin[k];
            pt->inv_size[k] = 1.0f / sp->size[k];
        }
        if (sp->kind == VBCL_PATTERN_FOURIER) {
            if (texgen_fourier_init(&pt->fourier, sp->terms, sp->contrast, sp->freq, sp->seed, perr,
                                    sizeof perr)) {
                snprintf(err, errlen, "%s: materials.%s.pattern: %s", s->path, s->materials[i].name,
                         perr);
                rc = 2;
            }
        } else {
            int w, h;
            float *img = NULL;
            if (texgen_projection_load(sp->image, &w, &h, &img, perr, sizeof perr)) {
                snprintf(err, errlen, "%s: materials.%s.pattern.image: %s", s->path,
                         s->materials[i].name, perr);
                rc = 2;
            } else {
                float *grown =
                    realloc(texels, sizeof(float) * 4 * (ntexels + (size_t)w * (size_t)h));
                if (!grown) {
                    rc = 1;
                    snprintf(err, errlen, "out of memory for the image %s", sp->image);
                } else {
                    texels = grown;
                    memcpy(texels + 4 * ntexels, img, sizeof(float) * 4 * (size_t)w * (size_t)h);
                    pt->width = w;
                    pt->height = h;
                    pt->texel_offset = (unsigned)ntexels;
                    ntexels += (size_t)w * (size_t)h;
                }
            }
            free(img);
        }
        mats[i].pattern = npats++;
    }
    if (!rc && (r->features & VBCL_FEATURE_DISPERSION)) {
        /* the side data after the images: the bands' rgb weights, then per dispersive
         * material its band table (eta, transmitted fraction) at each band's centre */
        int nb = s->bands, ndisp = 0;
        for (int i = 0; i < s->nmaterials; i++) ndisp += mats[i].disp >= 0;
        float *grown =
            realloc(texels, sizeof(float) * 4 * (ntexels + (size_t)nb * (size_t)(1 + ndisp)));
        if (!grown) {
            rc = 1;
            snprintf(err, errlen, "out of memory for the band tables");
        } else {
            texels = grown;
            DispBand band[DISP_MAX_BANDS];
            disp_layout_bands(s->band_layout, nb, band);
            r->band_weights = (unsigned)(4 * ntexels);
            for (int b = 0; b < nb; b++, ntexels++) {
                float *t = texels + 4 * ntexels;
                memcpy(t, band[b].rgb, sizeof band[b].rgb);
                t[3] = (float)band[b].centre;
            }
            for (int i = 0; i < s->nmaterials; i++) {
                if (mats[i].disp < 0) continue;
                const DispModel *d = &s->materials[i].disp;
                mats[i].disp = (int)(4 * ntexels);
                for (int b = 0; b < nb; b++, ntexels++) {
                    float *t = texels + 4 * ntexels;
                    t[0] = (float)disp_eta(d, band[b].centre);
                    t[1] = (float)disp_band_transmit(d, band[b].lo, band[b].hi);
                    t[2] = t[3] = 0.0f;
                }
            }
        }
    } else {
        for (int i = 0; i < s->nmaterials; i++) mats[i].disp = -1;
    }
    if (!rc) {
        r->patterns = clu_buffer(r->dev, pats, sizeof *pats * (size_t)npats, CL_MEM_READ_ONLY);
        r->texels = clu_buffer(r->dev, texels, sizeof(float) * 4 * ntexels, CL_MEM_READ_ONLY);
        if (!r->patterns || !r->texels) {
            snprintf(err, errlen, "%s: %s", r->dev->name, clu_error());
            rc = 1;
        }
    }
    free(pats);
    free(texels);
    return rc;
}

int renderer_set_scene_args(const Renderer *r, cl_kernel k)
{
    const cl_mem *m[RENDER_SCENE_ARGS] = {&r->frame,     &r->tris,      &r->normals, &r->cell_start,
                                          &r->cell_tris, &r->materials, &r->objects, &r->lights,
                                          &r->patterns,  &r->texels};
    for (cl_uint i = 0; i < RENDER_SCENE_ARGS; i++)
        if (clu_set_arg(k, i, sizeof(cl_mem), m[i])) return -1;
    return 0;
}

int renderer_set_frame_args(const Renderer *r, cl_kernel k, cl_mem rays, int nrays, cl_mem hits,
                            cl_mem media, cl_mem radiance, cl_mem counters)
{
    const cl_uint a = RENDER_SCENE_ARGS;
    if (renderer_set_scene_args(r, k) || clu_set_arg(k, a, sizeof(cl_mem), &rays) ||
        clu_set_arg(k, a + 1, sizeof(int), &nrays) ||
        clu_set_arg(k, a + 2, sizeof(cl_mem), &hits) ||
        clu_set_arg(k, a + 3, sizeof(cl_mem), &media) ||
        clu_set_arg(k, a + 4, sizeof(cl_mem), &radiance) ||
        clu_set_arg(k, a + 5, sizeof(cl_mem), &counters))
        return -1;
    return 0;
}

int renderer_fit_local_size(Renderer *r, cl_kernel k)
{
    size_t max = 0;
    if (!k) return 0;
    if (clGetKernelWorkGroupInfo(k, r->dev->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof max, &max,
                                 NULL) != CL_SUCCESS ||
        max < r->local_size)
        r->local_size = 0;
    return 0;
}

const size_t *renderer_local(const Renderer *r, size_t global)
{
    return r->local_size && global % r->local_size == 0 ? &r->local_size : NULL;
}

int renderer_init(Renderer *r, VbDevice *dev, const Scene *s, const char *extra_options,
                  RenderStats *st, char *err, size_t errlen)
{
    memset(r, 0, sizeof *r);
    r->dev = dev;
    clu_error_clear();
    char gerr[256];
    const int *res = (s->grid_res[0] > 0) ? s->grid_res : NULL;
    if (grid_build(&r->grid, &s->mesh, res, s->grid_density, gerr, sizeof gerr)) {
        snprintf(err, errlen, "%s: grid: %s", s->path, gerr);
        return 2;
    }
    st->grid_ms = r->grid.build_ms;

    r->features = features_of_scene(s);
    st->features = r->features;
    features_build_options(r->features, s, extra_options, st->options, sizeof st->options);
    r->program =
        clu_program_build(dev, vbcl_kernel_source, st->options, &st->build_ms, &st->build_cached);
    if (!r->program) goto fail;
    cl_int rc;
    r->k_camera = clCreateKernel(r->program, "camera_generate_rays", &rc);
    CL_CHECK_ERR(rc, "clCreateKernel(camera_generate_rays)", fail);
    r->k_intersect = clCreateKernel(r->program, "scene_intersect_closest", &rc);
    CL_CHECK_ERR(rc, "clCreateKernel(scene_intersect_closest)", fail);
    r->k_shading = clCreateKernel(r->program, "light_sample_shading", &rc);
    CL_CHECK_ERR(rc, "clCreateKernel(light_sample_shading)", fail);
    if (r->features & VBCL_FEATURE_TRANSPARENCY) {
        r->k_tree = clCreateKernel(r->program, "tree_trace_secondary", &rc);
        CL_CHECK_ERR(rc, "clCreateKernel(tree_trace_secondary)", fail);
        if (r->features & VBCL_FEATURE_DISPERSION) {
            r->k_bands = clCreateKernel(r->program, "tree_trace_bands", &rc);
            CL_CHECK_ERR(rc, "clCreateKernel(tree_trace_bands)", fail);
        }
    }

    r->local_size = dev->max_wg >= 64 ? 64 : 0;
    renderer_fit_local_size(r, r->k_intersect);
    renderer_fit_local_size(r, r->k_shading);
    renderer_fit_local_size(r, r->k_tree);
    renderer_fit_local_size(r, r->k_bands);

    double t0 = clu_now_ms();
    VbTriangle *tris = pack_triangles(s);
    VbTriNormals *normals = pack_normals(s);
    if (!tris || !normals) {
        free(tris);
        free(normals);
        snprintf(err, errlen, "out of memory packing %u triangles", s->mesh.ntris);
        renderer_release(r);
        return 1;
    }
    size_t nbytes_tris = sizeof(VbTriangle) * s->mesh.ntris;
    if (nbytes_tris > dev->max_alloc || sizeof(uint32_t) * (size_t)r->grid.nrefs > dev->max_alloc) {
        free(tris);
        free(normals);
        snprintf(err, errlen,
                 "%s: the scene (%u triangles, %u grid references) does not fit in "
                 "one allocation on %s (%.0f MiB at most)",
                 s->path, s->mesh.ntris, r->grid.nrefs, dev->name,
                 (double)dev->max_alloc / 1048576.0);
        renderer_release(r);
        return 2;
    }
    r->tris = clu_buffer(dev, tris, nbytes_tris, CL_MEM_READ_ONLY);
    r->normals = clu_buffer(
        dev, normals,
        (r->features & VBCL_FEATURE_SMOOTH_NORMALS) ? sizeof(VbTriNormals) * s->mesh.ntris : 0,
        CL_MEM_READ_ONLY);
    free(tris);
    free(normals);
    r->cell_start = clu_buffer(dev, r->grid.cell_start, sizeof(uint32_t) * (r->grid.ncells + 1u),
                               CL_MEM_READ_ONLY);
    r->cell_tris =
        clu_buffer(dev, r->grid.cell_tris, sizeof(uint32_t) * r->grid.nrefs, CL_MEM_READ_ONLY);
    /* the scene's materials, then the medium outside every host: vacuum, eta 1 */
    VbMaterial *mats = calloc((size_t)s->nmaterials + 1, sizeof *mats);
    VbObject *objs = calloc((size_t)s->nobjects, sizeof *objs);
    if (!mats || !objs) {
        free(mats);
        free(objs);
        goto fail;
    }
    for (int i = 0; i < s->nmaterials; i++) mats[i] = s->materials[i].gpu;
    mats[s->nmaterials].eta = 1.0f;
    mats[s->nmaterials].pattern = -1;
    mats[s->nmaterials].disp = -1;
    int prc = upload_patterns(r, s, mats, err, errlen);
    if (prc) {
        free(mats);
        free(objs);
        renderer_release(r);
        return prc;
    }
    mats[s->nmaterials].k_global = 1.0f;
    for (int i = 0; i < s->nobjects; i++) {
        const SceneObject *o = &s->objects[i];
        objs[i].material = (unsigned)o->material;
        objs[i].tex_material = o->tex_slot >= 0 ? (unsigned)o->tex_material : (unsigned)o->material;
        objs[i].tex_slot = o->tex_slot;
        objs[i].flags = o->is_host ? VBCL_OBJECT_HOST : 0u;
    }
    r->materials =
        clu_buffer(dev, mats, sizeof *mats * ((size_t)s->nmaterials + 1), CL_MEM_READ_ONLY);
    r->objects = clu_buffer(dev, objs, sizeof *objs * (size_t)s->nobjects, CL_MEM_READ_ONLY);
    free(mats);
    free(objs);
    r->lights = clu_buffer(dev, s->lights, sizeof(VbLight) * (size_t)s->nlights, CL_MEM_READ_ONLY);
    if (!r->tris || !r->normals || !r->cell_start || !r->cell_tris || !r->materials ||
        !r->objects || !r->lights)
        goto fail;

    /* frame constants */
    VbFrame *f = &r->frame_host;
    memset(f, 0, sizeof *f);
    frame_camera(s, &f->camera);
    frame_grid(&r->grid, &f->grid);
    memcpy(f->background, s->background, sizeof s->background);
    memcpy(f->ambient, s->ambient, sizeof s->ambient);
    f->width = s->width;
    f->height = s->height;
    f->nlights = (unsigned)s->nlights;
    f->ntris = s->mesh.ntris;
    unsigned strata = (unsigned)lround(sqrt((double)s->shadow_samples));
    f->shadow_strata = strata < 1 ? 1 : strata;
    f->seed = s->seed;
    f->flags = s->shadow_jitter ? 0u : VBCL_FRAME_FIXED_FEELERS;
    scene_medium_at(s, s->eye, &f->camera_medium);
    f->air_material = (unsigned)s->nmaterials;
    f->min_weight = s->min_weight;
    f->max_depth = s->max_depth;
    f->bands = s->bands;
    f->band_weights = r->band_weights;
    r->frame = clu_buffer(dev, NULL, sizeof *f, CL_MEM_READ_ONLY);

    /* tiles: bounded so that 32-bit work counters of one tile cannot overflow */
    long npix = (long)s->width * s->height;
    long per_pixel = 1 + (long)s->nlights * (long)(f->shadow_strata * f->shadow_strata);
    long tile = 65536;
    while (tile > 256 && tile * per_pixel > (1L << 24)) tile /= 2;
    if (tile > npix) tile = npix;
    r->tile_pixels = (int)tile;
    /* supersampling batches hold at least one pixel's 16x16 samples */
    long cap = tile < AA_MIN_BATCH_RAYS ? AA_MIN_BATCH_RAYS : tile;
    r->ray_capacity = (int)cap;
    r->rays = clu_buffer(dev, NULL, sizeof(VbRay) * (size_t)cap, CL_MEM_READ_WRITE);
    r->hits = clu_buffer(dev, NULL, sizeof(VbHit) * (size_t)cap, CL_MEM_READ_WRITE);
    r->radiance = clu_buffer(dev, NULL, sizeof(float) * 4 * (size_t)cap, CL_MEM_READ_WRITE);
    r->media = clu_buffer(dev, NULL, sizeof(VbMedium) * (size_t)cap, CL_MEM_READ_WRITE);
    r->counters = clu_buffer(dev, NULL, sizeof(cl_uint) * VBCL_COUNTERS, CL_MEM_READ_WRITE);
    if (!r->frame || !r->rays || !r->hits || !r->radiance || !r->media || !r->counters) goto fail;
    if (r->k_bands) {
        r->splits = clu_buffer(dev, NULL, sizeof(VbSplitSet) * (size_t)cap, CL_MEM_READ_WRITE);
        if (!r->splits) goto fail;
    }
    st->upload_ms = clu_now_ms() - t0;
    st->tile_pixels = r->tile_pixels;
    return 0;
fail:
    snprintf(err, errlen, "%s: %s", dev->name, clu_error()[0] ? clu_error() : "out of memory");
    renderer_release(r);
    return 1;
}

static void progress_report(double t_start, long done, long total, int *shown)
{
    double el = clu_now_ms() - t_start;
    if (el < 1000.0 && !*shown) return;
    double eta = done > 0 ? el * (double)(total - done) / (double)done : 0.0;
    fprintf(stderr, "\rvbcl: rendering %3.0f%%  (%.1f s elapsed, about %.1f s left) ",
            100.0 * (double)done / (double)total, el / 1000.0, eta / 1000.0);
    *shown = 1;
}

int renderer_trace_rays(Renderer *r, int n, RenderStats *st, double *trace_ms)
{
    VbDevice *d = r->dev;
    cl_event ev[4] = {0};
    cl_uint zero[VBCL_COUNTERS] = {0}, counts[VBCL_COUNTERS];
    size_t global = ((size_t)n + 63) / 64 * 64;
    int rc = -1;
    CL_CHECK(
        clEnqueueWriteBuffer(d->queue, r->counters, CL_FALSE, 0, sizeof zero, zero, 0, NULL, NULL),
        done);
    /* first interfaces, local shading, with dielectrics the ray trees, and with dispersion
     * the dispersive subtrees the trees left in r->splits */
    cl_kernel stages[4] = {r->k_intersect, r->k_shading, r->k_tree, r->k_bands};
    for (int k = 0; k < 4; k++) {
        if (!stages[k]) continue;
        if (renderer_set_frame_args(r, stages[k], r->rays, n, r->hits, r->media, r->radiance,
                                    r->counters))
            goto done;
        if (k >= 2 && r->k_bands &&
            clu_set_arg(stages[k], RENDER_SCENE_ARGS + 6, sizeof(cl_mem), &r->splits))
            goto done;
        CL_CHECK(clEnqueueNDRangeKernel(d->queue, stages[k], 1, NULL, &global,
                                        renderer_local(r, global), 0, NULL, &ev[k]),
                 done);
    }
    CL_CHECK(clEnqueueReadBuffer(d->queue, r->counters, CL_TRUE, 0, sizeof counts, counts, 0, NULL,
                                 NULL),
             done);
    double ms[4];
    for (int k = 0; k < 4; k++) ms[k] = ev[k] ? clu_event_ms(ev[k]) : 0.0;
    st->intersect_ms += ms[0];
    st->shading_ms += ms[1];
    st->tree_ms += ms[2];
    st->dispersion_ms += ms[3];
    if (trace_ms) *trace_ms += ms[0] + ms[1] + ms[2] + ms[3];
    st->rays_primary += (unsigned long long)n;
#define RENDER_ADD_COUNTER(name, index, field, group, key) st->field += counts[VBCL_COUNT_##name];
    VBCL_COUNTER_LIST(RENDER_ADD_COUNTER)
#undef RENDER_ADD_COUNTER
    st->by_depth[0] += (unsigned long long)n;
    for (int k = 1; k < VBCL_COUNT_DEPTH_BINS; k++)
        st->by_depth[k] += counts[VBCL_COUNT_DEPTH0 + k];
    rc = 0;
done:
    for (int i = 0; i < 4; i++)
        if (ev[i]) clReleaseEvent(ev[i]);
    return rc;
}

/* Pass 0: one ray through the centre of each pixel, tile by tile, into rgba. */
static int render_pixel_centres(Renderer *r, const Scene *s, float *rgba, RenderStats *st,
                                int progress, char *err, size_t errlen)
{
    VbDevice *d = r->dev;
    VbFrame *f = &r->frame_host;
    long npix = (long)s->width * s->height;
    double t_start = clu_now_ms();
    int shown = 0;
    for (long first = 0; first < npix; first += r->tile_pixels) {
        int n = (int)((npix - first) < r->tile_pixels ? (npix - first) : r->tile_pixels);
        f->first_pixel = (int)first;
        f->tile_pixels = n;
        cl_event ev[2] = {0};
        size_t global = ((size_t)n + 63) / 64 * 64;
        CL_CHECK(clEnqueueWriteBuffer(d->queue, r->frame, CL_FALSE, 0, sizeof *f, f, 0, NULL, NULL),
                 fail);
        if (renderer_set_frame_args(r, r->k_camera, r->rays, n, r->hits, r->media, r->radiance,
                                    r->counters))
            goto fail;
        CL_CHECK(
            clEnqueueNDRangeKernel(d->queue, r->k_camera, 1, NULL, &global, NULL, 0, NULL, &ev[0]),
            fail);
        if (renderer_trace_rays(r, n, st, NULL)) goto fail;
        CL_CHECK(clEnqueueReadBuffer(d->queue, r->radiance, CL_TRUE, 0,
                                     sizeof(float) * 4 * (size_t)n, rgba + 4 * first, 0, NULL,
                                     &ev[1]),
                 fail);
        st->camera_ms += clu_event_ms(ev[0]);
        st->readback_ms += clu_event_ms(ev[1]);
        for (int i = 0; i < 2; i++)
            if (ev[i]) clReleaseEvent(ev[i]);
        st->tiles++;
        if (progress) progress_report(t_start, first + n, npix, &shown);
        continue;
    fail:
        for (int i = 0; i < 2; i++)
            if (ev[i]) clReleaseEvent(ev[i]);
        if (shown) fputc('\n', stderr);
        snprintf(err, errlen, "%s: %s", d->name, clu_error());
        return 1;
    }
    if (shown)
        fprintf(stderr, "\rvbcl: rendering 100%% (%.1f s)%30s\n", (clu_now_ms() - t_start) / 1000.0,
                "");
    return 0;
}

int renderer_render(Renderer *r, const Scene *s, float *rgba, RenderStats *st, int progress,
                    char *err, size_t errlen)
{
    long npix = (long)s->width * s->height;
    double t_start = clu_now_ms();
    int rc;
    clu_error_clear();
    free(r->aa_levels);
    r->aa_levels = NULL;
    if (s->ssaa > 1) {
        rc = aa_supersample(r, s, s->ssaa, rgba, st, err, errlen);
    } else {
        rc = render_pixel_centres(r, s, rgba, st, progress, err, errlen);
        st->samples = (unsigned long long)npix;
        st->samples_max = 1;
        unsigned long long centres = st->rays_primary;
        if (!rc && s->aa_threshold > 0.0f) rc = aa_refine(r, s, rgba, st, err, errlen);
        st->rays_refine = st->rays_primary - centres; /* a ray kind of its own in --stats */
        st->rays_primary = centres;
    }
    st->render_ms = clu_now_ms() - t_start;
    return rc;
}

void renderer_release(Renderer *r)
{
    cl_mem *mems[] = {&r->tris,    &r->normals, &r->cell_start, &r->cell_tris, &r->materials,
                      &r->objects, &r->lights,  &r->patterns,   &r->texels,    &r->frame,
                      &r->rays,    &r->hits,    &r->media,      &r->radiance,  &r->counters,
                      &r->aa_pass, &r->film,    &r->levels,     &r->marks,     &r->mark_counts,
                      &r->splits};
    for (size_t i = 0; i < sizeof mems / sizeof mems[0]; i++)
        if (*mems[i]) {
            CL_WARN(clReleaseMemObject(*mems[i]));
            *mems[i] = NULL;
        }
    cl_kernel *ks[] = {&r->k_camera, &r->k_intersect,   &r->k_shading,     &r->k_tree,
                       &r->k_bands,  &r->k_aa_generate, &r->k_aa_contrast, &r->k_aa_reconstruct};
    for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
        if (*ks[i]) {
            CL_WARN(clReleaseKernel(*ks[i]));
            *ks[i] = NULL;
        }
    if (r->program) CL_WARN(clReleaseProgram(r->program));
    r->program = NULL;
    free(r->aa_levels);
    r->aa_levels = NULL;
    grid_free(&r->grid);
}
