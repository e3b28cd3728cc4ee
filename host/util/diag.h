/* diag.h — the one formatter of every message vbcl shows a user: control characters
 * (newline, ESC, ...) appear as \xNN, and values echoed back are cut to DIAG_VALUE_MAX
 * characters, so that every message stays one harmless line. */
#ifndef VBCL_DIAG_H
#define VBCL_DIAG_H

#include <stdarg.h>
#include <stddef.h>

#define DIAG_VALUE_MAX 80

/* Formats fmt (printf rules) into out, showing every control character as \xNN.
 * Returns out. */
char *diag_vformat(char *out, size_t n, const char *fmt, va_list ap);
char *diag_format(char *out, size_t n, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Prints "PREFIX: message\n" on stderr, the message formatted as diag_format. */
void diag_print(const char *prefix, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* A value the user gave (an argument, a key, a name), ready to echo: control characters
 * as \xNN, cut to DIAG_VALUE_MAX characters with "...". The result lives in one of 8
 * rotating static buffers (enough for one message). */
const char *diag_value(const char *s);

/* A limit for a range message: integers as integers (2147483647, not 2.14748e+09),
 * other numbers as %g. Rotating static buffers, like diag_value. */
const char *diag_num(double v);

/* The choice nearest to word, for "did you mean ...?": a name other renderers use for it
 * (`ior` for eta, `center` and `position` for centre, `color` for diffuse: the choice must be
 * among choices), else the closest by edit distance (insertions, deletions, substitutions
 * and swaps of neighbours, case ignored) when it is at most a third of the word's length
 * (1 for short words). choices ends with NULL. Returns NULL when none is near. */
const char *diag_suggest(const char *word, const char *const *choices);

#endif
