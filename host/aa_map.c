/* aa_map.c — the --aa-map and --aa-samples-map images: the heat map and its legend. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "aa.h"
#include "aa_map.h"
#include "font.h"

/* The legend's proportions, in units of lg->scale: margins, a level's pitch and its
 * swatch's height, the bar's width, the gap from bar to label, the tick's length. */
#define LEGEND_PAD           3 /* white columns between the map and the bar */
#define LEGEND_TOP           2 /* rows above the first level's band */
#define LEGEND_PITCH         8 /* rows from one level's centre to the next */
#define LEGEND_SWATCH        6
#define LEGEND_BAR_W         6
#define LEGEND_GAP           3   /* columns from the bar to the label (the tick takes 2 of them) */
#define LEGEND_RIGHT         2   /* columns after the widest label */
#define LEGEND_ROWS_PER_UNIT 160 /* a map this many rows tall gets a unit of 2 pixels, ... */

void aa_map_legend(int map_w, int map_h, int samples, int max_level, AaMapLegend *lg)
{
    int k = map_h / LEGEND_ROWS_PER_UNIT;
    k = k < 1 ? 1 : k > 32 ? 32 : k;
    max_level = max_level < 1 ? 1 : max_level > VBCL_AA_MAX_LEVEL ? VBCL_AA_MAX_LEVEL : max_level;
    char widest[8];
    aa_map_label(max_level, samples, widest, sizeof widest);
    lg->map_w = map_w;
    lg->map_h = map_h;
    lg->scale = k;
    lg->max_level = max_level;
    lg->samples = samples;
    lg->bar_x = map_w + LEGEND_PAD * k;
    lg->bar_w = LEGEND_BAR_W * k;
    lg->half = LEGEND_SWATCH * k / 2;
    lg->tick_x = lg->bar_x + lg->bar_w;
    lg->tick_w = samples ? 2 * k : 0;
    lg->label_x = lg->bar_x + lg->bar_w + LEGEND_GAP * k;
    lg->width = lg->label_x + font_text_width(widest, k) + LEGEND_RIGHT * k;
    for (int j = 0; j <= VBCL_AA_MAX_LEVEL; j++)
        lg->centre[j] = (LEGEND_TOP + (max_level - j) * LEGEND_PITCH + LEGEND_PITCH / 2) * k;
    int legend_h = (2 * LEGEND_TOP + (max_level + 1) * LEGEND_PITCH) * k;
    lg->height = map_h > legend_h ? map_h : legend_h;
}

char *aa_map_label(int level, int samples, char *buf, size_t n)
{
    snprintf(buf, n, "%d", samples ? 1 << (2 * level) : level);
    return buf;
}

/* Sets pixel (x, y) of the legend image to rgb (alpha 1). */
static void legend_put(float *img, const AaMapLegend *lg, int x, int y, const float rgb[3])
{
    float *o = img + 4 * ((size_t)y * (size_t)lg->width + (size_t)x);
    o[0] = rgb[0];
    o[1] = rgb[1];
    o[2] = rgb[2];
    o[3] = 1.0f;
}

/* Draws the legend of lg into img (white already): swatches or the bar, ticks, labels. */
static void legend_draw(float *img, const AaMapLegend *lg)
{
    static const float ink[3] = {0.0f, 0.0f, 0.0f};
    int top = lg->centre[lg->max_level] - lg->half, bottom = lg->centre[0] + lg->half;
    for (int y = top; y < bottom; y++) {
        float rgb[3];
        int level = -1;
        for (int j = 0; j <= lg->max_level; j++)
            if (y >= lg->centre[j] - lg->half && y < lg->centre[j] + lg->half) level = j;
        if (lg->samples) {
            /* the bar: the level position of row y, and the sample count nearest to it */
            double v = (double)(lg->centre[0] - y) / (double)(lg->centre[0] - lg->centre[1]);
            v = v < 0.0 ? 0.0 : v > lg->max_level ? lg->max_level : v;
            aa_samples_colour((int)lround(pow(4.0, v)), rgb);
        } else if (level >= 0) {
            aa_level_colour(level, rgb);
        } else {
            continue; /* between two swatches */
        }
        for (int x = lg->bar_x; x < lg->bar_x + lg->bar_w; x++) legend_put(img, lg, x, y, rgb);
    }
    for (int j = 0; j <= lg->max_level; j++) {
        char label[8];
        aa_map_label(j, lg->samples, label, sizeof label);
        int k = lg->scale;
        for (int y = lg->centre[j] - k / 2; y < lg->centre[j] - k / 2 + k && lg->tick_w; y++)
            for (int x = lg->tick_x; x < lg->tick_x + lg->tick_w; x++)
                legend_put(img, lg, x, y, ink);
        font_draw(img, lg->width, lg->height, lg->label_x, lg->centre[j] - FONT_GLYPH_H * k / 2, k,
                  label, ink);
    }
}

float *aa_map_image(const int *values, int map_w, int map_h, int samples, int max_level,
                    AaMapLegend *lg)
{
    aa_map_legend(map_w, map_h, samples, max_level, lg);
    size_t npix = (size_t)lg->width * (size_t)lg->height;
    float *img = malloc(sizeof(float) * 4 * npix);
    if (!img) return NULL;
    for (size_t i = 0; i < 4 * npix; i++) img[i] = 1.0f;
    for (int y = 0; y < map_h; y++)
        for (int x = 0; x < map_w; x++) {
            float *o = img + 4 * ((size_t)y * (size_t)lg->width + (size_t)x);
            int v = values[(size_t)y * (size_t)map_w + (size_t)x];
            if (samples)
                aa_samples_colour(v, o);
            else
                aa_level_colour(v, o);
        }
    legend_draw(img, lg);
    return img;
}
