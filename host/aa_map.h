/* aa_map.h — the images of --aa-map and --aa-samples-map: each pixel's refinement level or
 * sample count as a heat map (aa_level_colour, aa_samples_colour), with a legend strip to
 * its right: the colour of each level and its number (docs/scene-format.md). */
#ifndef VBCL_AA_MAP_H
#define VBCL_AA_MAP_H

#include <stddef.h>

#include "types.h"

/* Where a heat map and its legend lie in the image. The map is the image's top-left
 * map_w x map_h pixels, exactly as without a legend; the strip fills the columns from
 * map_w on (and the rows below the map where the legend is the taller), white. Levels run
 * from max_level at the top to 0 at the bottom, each centred on row centre[level]: the
 * level map has a swatch of the level's colour there (rows centre - half to centre +
 * half - 1), the samples map a continuous bar over all of them, each row of it the colour
 * of a sample count the map can show (4^level on a level's centre row) and a black tick
 * beside each centre; right of it the label, in black: the level, or 4^level samples. */
typedef struct AaMapLegend {
    int map_w, map_h;                  /* the heat map */
    int width, height;                 /* the whole image */
    int scale;                         /* the legend's unit: a font pixel's side */
    int max_level;                     /* the deepest level shown (1..VBCL_AA_MAX_LEVEL) */
    int samples;                       /* 1: the samples map's legend, 0: the level map's */
    int bar_x, bar_w;                  /* the swatches' (or the bar's) columns */
    int half;                          /* a swatch's rows either side of its centre */
    int tick_x, tick_w;                /* the ticks' columns (the samples map only) */
    int label_x;                       /* the labels' left column */
    int centre[VBCL_AA_MAX_LEVEL + 1]; /* each level's centre row */
} AaMapLegend;

/* The legend's layout for a map_w x map_h map (each at least 1) of levels 0..max_level
 * (clamped to 1..VBCL_AA_MAX_LEVEL), the samples map's when samples is set. */
void aa_map_legend(int map_w, int map_h, int samples, int max_level, AaMapLegend *lg);

/* The label of level at in a legend: "3" for the level map, "64" (4^level) for the samples
 * map; buf holds at least 8 characters. Returns buf. */
char *aa_map_label(int level, int samples, char *buf, size_t n);

/* The heat map of values (map_w x map_h: levels, or with samples set sample counts) with
 * its legend, as linear RGBA (alpha 1), laid out as aa_map_legend's *lg (filled here).
 * Returns the malloc'ed image of lg->width x lg->height pixels, or NULL out of memory. */
float *aa_map_image(const int *values, int map_w, int map_h, int samples, int max_level,
                    AaMapLegend *lg);

#endif
