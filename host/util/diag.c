/* diag.c — message formatting shared by the command line, the scene and mesh loaders and
 * texgen (diag.h). */
#include "diag.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

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
