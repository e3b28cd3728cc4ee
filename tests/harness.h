/* harness.h — the whole test harness: named tests, checks that report where they failed,
 * and a closing line "N passed, N failed" (a test passes when none of its checks fail). */
#ifndef VBCL_HARNESS_H
#define VBCL_HARNESS_H

#include <stdio.h>

extern int th_checks_failed; /* failed checks in the running test */

/* Records a failed check with its location and a printf-style explanation; the first
 * 8 failures of a test are printed, the rest only counted. */
void th_fail(const char *file, int line, const char *expr, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) th_fail(__FILE__, __LINE__, #cond, __VA_ARGS__);                              \
    } while (0)

/* Runs fn as one test unless a name filter excludes it; prints "ok NAME (T s)" or
 * "FAIL NAME (N failed checks, T s)", T its wall time. */
void th_run(const char *name, void (*fn)(void));
#define RUN_TEST(fn) th_run(#fn, fn)

/* Marks the running test skipped (counted apart, never as passed) and says why. */
void th_skip(const char *why);

/* Runs only tests whose name contains f (NULL: all). */
void th_set_filter(const char *f);

/* Runs the tests in `jobs` worker processes (at most TH_MAX_JOBS; fewer than 2: in this
 * one, and it returns). Each worker is this program again (argv with "--worker K FD" after
 * argv[0], FD the shared counts); it walks every suite and takes each test no other worker
 * has taken, so a long test holds one worker while the others go on, and a test's output is
 * written whole when it ends. The caller, the parent, waits for the workers, names any that
 * crashed and the test it was in, prints the summary and exits (1 if any test failed). */
#define TH_MAX_JOBS 16
void th_parallel(int jobs, char **argv);

/* Puts the tests run from here on, until th_group(NULL), in group `name`: with workers,
 * one worker runs all of a group's tests (tests that would otherwise compile the same
 * kernels at the same time in two workers). */
void th_group(const char *name);

/* Makes this process worker k of th_parallel, sharing counts through fd; -1 on failure. */
int th_worker(int k, int fd);

/* Prints "N passed, N failed[, N skipped]" and returns the exit status (1 if any failed);
 * in a worker it prints nothing and returns 0 (the parent prints the summary). */
int th_summary(void);

#endif
