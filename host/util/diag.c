/* diag.c — message formatting shared by the command line, the scene and mesh loaders and
 * texgen (diag.h). */
#include "diag.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

/* Copies src into out (size n), control characters as \xNN; stops at max source
 * characters and appends "..." when src is longer. */
static void escape(char *out, size_t n, const char *src, size_t max)
{
    size_t k = 0, i = 0;
    if (n == 0) return;
    for (; src[i] && i < max; i++) {
        unsigned char ch = (unsigned char)src[i];
        if (ch < 0x20 || ch == 0x7f) {
            if (k + 4 >= n) break;
            snprintf(out + k, n - k, "\\x%02x", ch);
            k += 4;
        } else {
            if (k + 1 >= n) break;
            out[k++] = (char)ch;
        }
    }
    if (src[i] && i == max && k + 3 < n) {
        memcpy(out + k, "...", 3);
        k += 3;
    }
    out[k] = 0;
}

char *diag_vformat(char *out, size_t n, const char *fmt, va_list ap)
{
    char raw[4096];
    vsnprintf(raw, sizeof raw, fmt, ap);
    escape(out, n, raw, (size_t)-1);
    return out;
}

char *diag_format(char *out, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(out, n, fmt, ap);
    va_end(ap);
    return out;
}

void diag_print(const char *prefix, const char *fmt, ...)
{
    char msg[4096];
    va_list ap;
    va_start(ap, fmt);
    diag_vformat(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fprintf(stderr, "%s: %s\n", prefix, msg);
}

static char *next_buffer(void)
{
    static char bufs[8][4 * DIAG_VALUE_MAX + 8];
    static int next;
    next = (next + 1) % 8;
    return bufs[next];
}

const char *diag_value(const char *s)
{
    char *b = next_buffer();
    escape(b, 4 * DIAG_VALUE_MAX + 8, s ? s : "(null)", DIAG_VALUE_MAX);
    return b;
}

const char *diag_num(double v)
{
    char *b = next_buffer();
    if (v == floor(v) && fabs(v) < 1e18)
        snprintf(b, 4 * DIAG_VALUE_MAX, "%.0f", v);
    else
        snprintf(b, 4 * DIAG_VALUE_MAX, "%g", v);
    return b;
}

/* Edit distance with swaps of neighbours (optimal string alignment), case ignored; words
 * longer than 63 characters are compared by their first 63. */
static int edit_distance(const char *a, const char *b)
{
    int n = (int)strnlen(a, 63), m = (int)strnlen(b, 63);
    int d[64][64];
    for (int i = 0; i <= n; i++) d[i][0] = i;
    for (int j = 0; j <= m; j++) d[0][j] = j;
    for (int i = 1; i <= n; i++)
        for (int j = 1; j <= m; j++) {
            int ca = tolower((unsigned char)a[i - 1]), cb = tolower((unsigned char)b[j - 1]);
            int best = d[i - 1][j - 1] + (ca != cb);
            if (d[i - 1][j] + 1 < best) best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best) best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && ca == tolower((unsigned char)b[j - 2]) &&
                tolower((unsigned char)a[i - 2]) == cb && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[n][m];
}

/* Names other renderers and formats use, and vbcl's own for the same thing. */
static const char *const synonyms[][2] = {
    {"color", "diffuse"},      {"colour", "diffuse"},
    {"albedo", "diffuse"},     {"ior", "eta"},
    {"index", "eta"},          {"refractive_index", "eta"},
    {"center", "centre"},      {"position", "centre"},
    {"pos", "centre"},         {"position", "eye"},
    {"from", "eye"},           {"origin", "eye"},
    {"lookat", "look_at"},     {"target", "look_at"},
    {"to", "look_at"},         {"intensity", "flux"},
    {"power", "flux"},         {"absorption", "extinction"},
    {"sigma_a", "extinction"}, {"translation", "translate"},
    {"rotation", "rotate"},    {"scaling", "scale"},
    {"fov_y", "fov"},          {"samples", "shadow_samples"},
    {"depth", "max_depth"},    {"maxdepth", "max_depth"},
};

const char *diag_suggest(const char *word, const char *const *choices)
{
    for (size_t s = 0; s < sizeof synonyms / sizeof synonyms[0]; s++) {
        if (strcasecmp(word, synonyms[s][0])) continue;
        for (const char *const *c = choices; *c; c++)
            if (!strcmp(*c, synonyms[s][1])) return *c;
    }
    size_t len = strlen(word);
    int limit = len <= 4 ? 1 : (int)(len / 3), best = limit + 1;
    const char *pick = NULL;
    for (const char *const *c = choices; *c; c++) {
        int e = edit_distance(word, *c);
        if (e < best) {
            best = e;
            pick = *c;
        }
    }
    return pick;
}
