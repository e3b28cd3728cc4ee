/* frame.c — the frame driver: pass 0 tile by tile, then refinement (adaptive or uniform),
 * with the counts and times of each in RenderStats. The only module that uses both the
 * tracing layer (render.c) and anti-aliasing (aa.c). */
#include "frame.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Releases the devices' renderers and the anti-aliasing state, keeping fr->cs. */
static void frame_release_devices(Frame *fr)
{
    aa_release(&fr->aa);
    renderer_release(&fr->r);
    for (int i = 0; i < fr->nmore; i++) renderer_release(&fr->more[i]);
    free(fr->more);
    fr->more = NULL;
    fr->nmore = 0;
}

void frame_region(const Scene *s, int reg[4])
{
    int cropped = s->crop[2] > 0;
    reg[0] = cropped ? s->crop[0] : 0;
    reg[1] = cropped ? s->crop[1] : 0;
    reg[2] = cropped ? s->crop[2] : s->width;
    reg[3] = cropped ? s->crop[3] : s->height;
}

int frame_margin(const Scene *s)
{
    int reach = s->crop[2] > 0 ? aa_reach(s) : 0;
    return s->crop_margin >= 0 && s->crop_margin < reach ? s->crop_margin : reach;
}

void frame_window(const Scene *s, int win[4])
{
    frame_region(s, win);
    int m = frame_margin(s), lim[4] = {0, 0, s->width, s->height};
    for (int k = 0; k < 4; k++) {
        long v = win[k] + (k < 2 ? -(long)m : (long)m);
        win[k] = (int)(k < 2 ? (v < lim[k] ? lim[k] : v) : (v > lim[k] ? lim[k] : v));
    }
}

/* Sets the window of the compiled scene's frame constants to s's (frame_window). */
static void frame_set_window(CompiledScene *cs, const Scene *s)
{
    int win[4];
    frame_window(s, win);
    cs->frame.window_x = win[0];
    cs->frame.window_y = win[1];
    cs->frame.window_width = win[2] - win[0];
    cs->frame.window_height = win[3] - win[1];
}

/* Moves the region's pixels (reg) of an image of the window win, `size` bytes each, to the
 * start of img, row by row: in place, since each row moves to where it began or before. */
static void frame_cut(const int win[4], const int reg[4], void *img, size_t size)
{
    char *p = img;
    size_t ww = (size_t)(win[2] - win[0]), rw = (size_t)(reg[2] - reg[0]);
    for (int y = reg[1]; y < reg[3]; y++)
        memmove(p + (size_t)(y - reg[1]) * rw * size,
                p + ((size_t)(y - win[1]) * ww + (size_t)(reg[0] - win[0])) * size, rw * size);
}

int frame_init(Frame *fr, VbDevice *devs, int ndev, const Scene *s, RenderStats *st, char *err,
               size_t errlen)
{
    frame_release_devices(fr);
    char host[sizeof fr->work[0].host] = "";
    if (gethostname(host, sizeof host - 1)) host[0] = 0;
    for (int i = 0; i < ndev && i < CLU_MAX_DEVICES; i++) {
        memset(&fr->work[i], 0, sizeof fr->work[i]);
        snprintf(fr->work[i].name, sizeof fr->work[i].name, "%s", devs[i].name);
        fr->work[i].index = devs[i].index;
        memcpy(fr->work[i].host, host, sizeof host);
    }
    /* one compilation of the scene for every device (the camera tiles fit the smallest),
     * keeping the last frame's geometry where it is the same */
    size_t max_alloc = devs[0].max_alloc;
    for (int i = 1; i < ndev; i++)
        if (devs[i].max_alloc < max_alloc) max_alloc = devs[i].max_alloc;
    int rc = compiled_scene_update(&fr->cs, s, max_alloc, err, errlen);
    st->scene_compiles++;
    st->geometry_builds += fr->cs.geometry_built;
    st->grid_ms = fr->cs.geometry_built ? fr->cs.grid.build_ms : 0.0;
    frame_set_window(&fr->cs, s);
    if (!rc) rc = renderer_init_compiled(&fr->r, &devs[0], &fr->cs, s, NULL, st, err, errlen);
    if (rc || ndev < 2) return rc;
    fr->more = calloc((size_t)(ndev - 1), sizeof *fr->more);
    if (!fr->more) {
        snprintf(err, errlen, "out of memory");
        return 1;
    }
    for (int i = 1; i < ndev && !rc; i++) {
        RenderStats scratch; /* --stats reports the first device's build */
        memset(&scratch, 0, sizeof scratch);
        rc = renderer_init_compiled(&fr->more[i - 1], &devs[i], &fr->cs, s, NULL, &scratch, err,
                                    errlen);
        if (!rc) fr->nmore = i;
    }
    return rc;
}

Renderer *frame_renderer(Frame *fr, int i)
{
    return i == 0 ? &fr->r : &fr->more[i - 1];
}

int frame_devices(const Frame *fr)
{
    return 1 + fr->nmore;
}

int frame_pixel_centres(Frame *fr, float *rgba, RenderStats *st, int progress, char *err,
                        size_t errlen)
{
    Renderer *rs[CLU_MAX_DEVICES];
    int n = frame_devices(fr);
    for (int i = 0; i < n; i++) rs[i] = frame_renderer(fr, i);
    long npix = (long)fr->r.frame_host.window_width * fr->r.frame_host.window_height;
    return tiles_trace(rs, n, fr->tiles, npix, rgba, st, fr->work, progress, err, errlen);
}

int frame_render(Frame *fr, const Scene *s, float *rgba, RenderStats *st, int progress, char *err,
                 size_t errlen)
{
    long npix = (long)fr->r.frame_host.window_width * fr->r.frame_host.window_height;
    double t_start = clu_now_ms();
    int rc;
    clu_error_clear();
    free(fr->aa.levels_host);
    free(fr->aa.leaves_host);
    fr->aa.levels_host = fr->aa.leaves_host = NULL;
    RenderStats before = *st; /* refinement and supersampling: the first device's work */
    double t_first = t_start;
    if (s->ssaa > 1) {
        rc = aa_supersample(&fr->aa, &fr->r, s, s->ssaa, rgba, st, err, errlen);
    } else {
        rc = aa_check_fits(&fr->r, s, err, errlen);
        if (!rc) rc = frame_pixel_centres(fr, rgba, st, progress, err, errlen);
        before = *st;
        t_first = clu_now_ms();
        st->samples = (unsigned long long)npix;
        st->samples_max = 1;
        unsigned long long centres = st->rays_primary;
        if (!rc && s->aa_threshold > 0.0f)
            rc = aa_refine(&fr->aa, &fr->r, s, rgba, st, progress, err, errlen);
        st->rays_refine = st->rays_primary - centres; /* a ray kind of its own in --stats */
        st->rays_primary = centres;
    }
    int win[4], reg[4];
    frame_window(s, win);
    frame_region(s, reg);
    if (!rc) frame_cut(win, reg, rgba, sizeof(float) * 4);
    if (!rc && fr->aa.levels_host) frame_cut(win, reg, fr->aa.levels_host, sizeof(int));
    if (!rc && fr->aa.leaves_host) frame_cut(win, reg, fr->aa.leaves_host, sizeof(int));
    st->render_ms = clu_now_ms() - t_start;
    fr->work[0].rays += tiles_rays(st) - tiles_rays(&before);
    fr->work[0].kernel_ms += tiles_kernel_ms(st) - tiles_kernel_ms(&before);
    fr->work[0].busy_ms += clu_now_ms() - t_first;
    return rc;
}

const int *frame_levels(const Frame *fr)
{
    return fr->aa.levels_host;
}

const int *frame_leaves(const Frame *fr)
{
    return fr->aa.leaves_host;
}

void frame_release(Frame *fr)
{
    frame_release_devices(fr);
    compiled_scene_free(&fr->cs);
}
