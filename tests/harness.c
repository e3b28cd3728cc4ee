/* harness.c — the test runner's bookkeeping: pass/fail/skip per test and the summary. */
#include "harness.h"

#include <stdarg.h>
#include <string.h>
#include <time.h>

int th_checks_failed;
static int passed, failed, skipped, skipping;
static const char *filter;

void th_fail(const char *file, int line, const char *expr, const char *fmt, ...)
{
    if (++th_checks_failed > 8) return;
    fprintf(stderr, "    %s:%d: check failed: %s: ", file, line, expr);
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

void th_skip(const char *why)
{
    skipping = 1;
    fprintf(stderr, "    skipped: %s\n", why);
}

void th_run(const char *name, void (*fn)(void))
{
    if (filter && !strstr(name, filter)) return;
    th_checks_failed = 0;
    skipping = 0;
    fprintf(stderr, "  %s ...\n", name);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    fn();
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (th_checks_failed) {
        failed++;
        printf("FAIL %s (%d failed checks, %.1f s)\n", name, th_checks_failed, secs);
    } else if (skipping) {
        skipped++;
        printf("skip %s (%.1f s)\n", name, secs);
    } else {
        passed++;
        printf("ok   %s (%.1f s)\n", name, secs);
    }
    fflush(stdout);
}

void th_set_filter(const char *f)
{
    filter = f;
}

int th_summary(void)
{
    if (skipped)
        printf("%d passed, %d failed, %d skipped\n", passed, failed, skipped);
    else
        printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
