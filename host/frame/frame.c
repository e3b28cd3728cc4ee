/* frame.c — the frame driver: pass 0 tile by tile, then refinement (adaptive or uniform),
 * with the counts and times of each in RenderStats. The only module that uses both the
 * tracing layer (render.c) and anti-aliasing (aa.c). */
#include "frame.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int frame_init(Frame *fr, VbDevice *dev, const Scene *s, RenderStats *st, char *err, size_t errlen)
{
    memset(&fr->aa, 0, sizeof fr->aa);
    return renderer_init(&fr->r, dev, s, NULL, st, err, errlen);
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

/* Pass 0: one ray through the centre of each pixel, tile by tile, into rgba. */
static int frame_pixel_centres(Renderer *r, const Scene *s, float *rgba, RenderStats *st,
                               int progress, char *err, size_t errlen)
{
    long npix = (long)s->width * s->height;
    double t_start = clu_now_ms();
    int shown = 0;
    for (long first = 0; first < npix; first += r->tile_pixels) {
        int n = (int)((npix - first) < r->tile_pixels ? (npix - first) : r->tile_pixels);
        if (renderer_trace_tile(r, first, n, rgba, st)) {
            if (shown) fputc('\n', stderr);
            snprintf(err, errlen, "%s: %s", r->dev->name, clu_error());
            return 1;
        }
        if (progress) progress_report(t_start, first + n, npix, &shown);
    }
    if (shown)
        fprintf(stderr, "\rvbcl: rendering 100%% (%.1f s)%30s\n", (clu_now_ms() - t_start) / 1000.0,
                "");
    return 0;
}

int frame_render(Frame *fr, const Scene *s, float *rgba, RenderStats *st, int progress, char *err,
                 size_t errlen)
{
    long npix = (long)s->width * s->height;
    double t_start = clu_now_ms();
    int rc;
    clu_error_clear();
    free(fr->aa.levels_host);
    free(fr->aa.leaves_host);
    fr->aa.levels_host = fr->aa.leaves_host = NULL;
    if (s->ssaa > 1) {
        rc = aa_supersample(&fr->aa, &fr->r, s, s->ssaa, rgba, st, err, errlen);
    } else {
        rc = frame_pixel_centres(&fr->r, s, rgba, st, progress, err, errlen);
        st->samples = (unsigned long long)npix;
        st->samples_max = 1;
        unsigned long long centres = st->rays_primary;
        if (!rc && s->aa_threshold > 0.0f)
            rc = aa_refine(&fr->aa, &fr->r, s, rgba, st, progress, err, errlen);
        st->rays_refine = st->rays_primary - centres; /* a ray kind of its own in --stats */
        st->rays_primary = centres;
    }
    st->render_ms = clu_now_ms() - t_start;
    return rc;
}

const int *frame_levels(const Frame *fr)
{
    return fr->aa.levels_host;
}

void frame_release(Frame *fr)
{
    aa_release(&fr->aa);
    renderer_release(&fr->r);
}
