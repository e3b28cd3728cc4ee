/* font.c — the digits 0-9 as 3 x 5 bitmap glyphs, drawn into float images (font.h). */
#include <string.h>

#include "font.h"

/* Each glyph's rows, top first; bit 2 of a row is its left column. */
static const unsigned char glyphs[10][FONT_GLYPH_H] = {
    {7, 5, 5, 5, 7}, /* 0 */
    {2, 6, 2, 2, 7}, /* 1 */
    {7, 1, 7, 4, 7}, /* 2 */
    {7, 1, 7, 1, 7}, /* 3 */
    {5, 5, 7, 1, 1}, /* 4 */
    {7, 4, 7, 1, 7}, /* 5 */
    {7, 4, 7, 5, 7}, /* 6 */
    {7, 1, 1, 1, 1}, /* 7 */
    {7, 5, 7, 5, 7}, /* 8 */
    {7, 5, 7, 1, 7}, /* 9 */
};

int font_ink(char c, int col, int row)
{
    if (c < '0' || c > '9' || col < 0 || col >= FONT_GLYPH_W || row < 0 || row >= FONT_GLYPH_H)
        return 0;
    return (glyphs[c - '0'][row] >> (FONT_GLYPH_W - 1 - col)) & 1;
}

int font_text_width(const char *text, int scale)
{
    size_t n = strlen(text);
    return n ? (int)((n - 1) * FONT_ADVANCE + FONT_GLYPH_W) * scale : 0;
}

int font_draw(float *rgba, int width, int height, int x, int y, int scale, const char *text,
              const float rgb[3])
{
    for (const char *p = text; *p; p++)
        if (*p < '0' || *p > '9') return -1;
    for (int g = 0; text[g]; g++)
        for (int row = 0; row < FONT_GLYPH_H * scale; row++)
            for (int col = 0; col < FONT_GLYPH_W * scale; col++) {
                int px = x + g * FONT_ADVANCE * scale + col, py = y + row;
                if (px < 0 || px >= width || py < 0 || py >= height ||
                    !font_ink(text[g], col / scale, row / scale))
                    continue;
                float *o = rgba + 4 * ((size_t)py * (size_t)width + (size_t)px);
                o[0] = rgb[0];
                o[1] = rgb[1];
                o[2] = rgb[2];
                o[3] = 1.0f;
            }
    return 0;
}
