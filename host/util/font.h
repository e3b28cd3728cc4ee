/* font.h — a tiny built-in bitmap font: the digits 0-9 as 3 x 5 glyphs, drawn at an
 * integer scale into a float RGBA image (the legends of the --aa-map heat maps). */
#ifndef VBCL_FONT_H
#define VBCL_FONT_H

#define FONT_GLYPH_W 3 /* a glyph's columns, before scaling */
#define FONT_GLYPH_H 5 /* a glyph's rows, before scaling */
#define FONT_ADVANCE 4 /* columns from one glyph's left edge to the next's */

/* Whether column col (0..FONT_GLYPH_W-1) of row row (0..FONT_GLYPH_H-1, top first) of the
 * glyph of c is ink; 0 for a character without a glyph (anything but a digit) and outside
 * the glyph. */
int font_ink(char c, int col, int row);

/* Width in pixels of text drawn at scale (its glyphs and the spaces between them, none
 * after the last); 0 for an empty text. */
int font_text_width(const char *text, int scale);

/* Draws text with its top-left corner at (x, y) into rgba (width x height pixels, 4 floats
 * each), each glyph pixel a scale x scale square of colour rgb (alpha 1); pixels outside
 * the image are skipped, and only ink is drawn. Returns 0, or -1 (nothing drawn) when text
 * holds a character without a glyph. */
int font_draw(float *rgba, int width, int height, int x, int y, int scale, const char *text,
              const float rgb[3]);

#endif
