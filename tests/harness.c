/* harness.c — the test runner's bookkeeping: pass/fail/skip per test and the summary; with
 * th_parallel, several worker processes that share the tests out between them. */
#include "harness.h"

#include <fcntl.h>
#include <sched.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

enum { TH_MAX_TESTS = 1024, TH_MAX_FAILED = 64, TH_NAME = 96, TH_MAX_GROUPS = 16 };

/* What the workers share (a memfd mapped by each): which tests are taken, the counts,
 * the failed tests' names, what each worker runs, and the lock on the output. */
typedef struct {
    int claimed[TH_MAX_TESTS];
    int passed, failed, skipped, out_lock, group_lock;
    char groups[TH_MAX_GROUPS][TH_NAME]; /* th_group names, each with its worker */
    int group_owner[TH_MAX_GROUPS];
    char failed_names[TH_MAX_FAILED][TH_NAME];
    char running[TH_MAX_JOBS][TH_NAME];
    char output[TH_MAX_JOBS][64]; /* the file that holds the running test's output */
} Shared;

int th_checks_failed;
static int passed, failed, skipped, skipping;
static const char *filter;
static Shared *shared; /* NULL: one process */
static int worker, next_test;
static const char *group; /* th_group's */

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

/* Writes all of buf to fd 1 (a failed write is not reported: there is nowhere else). */
static void write_all(const char *buf, size_t n)
{
    while (n > 0) {
        ssize_t k = write(1, buf, n);
        if (k <= 0) return;
        buf += k;
        n -= (size_t)k;
    }
}

/* In a worker, sends fds 1 and 2 to a temporary file for one test (its output is shown
 * whole, after it ends, or by the parent if the worker dies in it: its name is in
 * shared->output); returns the file, or NULL where output goes straight out. */
static FILE *capture_begin(int saved[2])
{
    if (!shared) return NULL;
    char *path = shared->output[worker];
    snprintf(path, sizeof shared->output[0], "/tmp/vbcl-tests-out-XXXXXX");
    int fd = mkstemp(path);
    FILE *f = fd < 0 ? NULL : fdopen(fd, "w+");
    if (!f) {
        if (fd >= 0) close(fd);
        path[0] = 0;
        return NULL;
    }
    fflush(stdout);
    fflush(stderr);
    /* only fds 1 and 2 reach the test's own child processes (a test may set ulimit -n 4) */
    fcntl(fileno(f), F_SETFD, FD_CLOEXEC);
    saved[0] = fcntl(1, F_DUPFD_CLOEXEC, 0);
    saved[1] = fcntl(2, F_DUPFD_CLOEXEC, 0);
    dup2(fileno(f), 1);
    dup2(fileno(f), 2);
    return f;
}

/* Ends capture_begin's redirection and writes the test's output as one block. */
static void capture_end(FILE *f, const int saved[2])
{
    if (!f) return;
    fflush(stdout);
    fflush(stderr);
    dup2(saved[0], 1);
    dup2(saved[1], 2);
    close(saved[0]);
    close(saved[1]);
    long n = ftell(f);
    char *buf = n > 0 ? malloc((size_t)n) : NULL;
    size_t got = 0;
    if (buf && fseek(f, 0, SEEK_SET) == 0) got = fread(buf, 1, (size_t)n, f);
    fclose(f);
    unlink(shared->output[worker]);
    shared->output[worker][0] = 0;
    while (__atomic_exchange_n(&shared->out_lock, 1, __ATOMIC_ACQUIRE)) sched_yield();
    write_all(buf ? buf : "    (output lost: no memory)\n", buf ? got : 29);
    __atomic_store_n(&shared->out_lock, 0, __ATOMIC_RELEASE);
    free(buf);
}

/* Counts one result, in the shared counts where there are workers; returns the count
 * before it. */
static int count(int *mine, int *all)
{
    return shared ? __atomic_fetch_add(all, 1, __ATOMIC_SEQ_CST) : (*mine)++;
}

/* Whether this worker runs the tests of group g: the first worker to ask owns it (a table
 * too full to hold g: worker 0). */
static int group_mine(const char *g)
{
    while (__atomic_exchange_n(&shared->group_lock, 1, __ATOMIC_ACQUIRE)) sched_yield();
    int owner = 0, k = 0;
    while (k < TH_MAX_GROUPS && shared->groups[k][0] && strcmp(shared->groups[k], g)) k++;
    if (k < TH_MAX_GROUPS && !shared->groups[k][0]) {
        snprintf(shared->groups[k], TH_NAME, "%s", g);
        shared->group_owner[k] = worker;
    }
    if (k < TH_MAX_GROUPS) owner = shared->group_owner[k];
    __atomic_store_n(&shared->group_lock, 0, __ATOMIC_RELEASE);
    return owner == worker;
}

void th_group(const char *name)
{
    group = name;
}

void th_run(const char *name, void (*fn)(void))
{
    if (filter && !strstr(name, filter)) return;
    int index = next_test++;
    if (shared) { /* the first worker to come to a test takes it; past the table, worker 0 */
        int mine = group ? group_mine(group)
                   : index < TH_MAX_TESTS
                       ? !__atomic_exchange_n(&shared->claimed[index], 1, __ATOMIC_SEQ_CST)
                       : worker == 0;
        if (!mine) return;
        snprintf(shared->running[worker], TH_NAME, "%s", name);
    }
    int saved[2];
    FILE *cap = capture_begin(saved);
    th_checks_failed = 0;
    skipping = 0;
    fprintf(stderr, "  %s ...\n", name);
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    fn();
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    if (th_checks_failed) {
        int k = count(&failed, shared ? &shared->failed : NULL);
        printf("FAIL %s (%d failed checks, %.1f s)\n", name, th_checks_failed, secs);
        if (shared && k < TH_MAX_FAILED) snprintf(shared->failed_names[k], TH_NAME, "%s", name);
    } else if (skipping) {
        count(&skipped, shared ? &shared->skipped : NULL);
        printf("skip %s (%.1f s)\n", name, secs);
    } else {
        count(&passed, shared ? &shared->passed : NULL);
        printf("ok   %s (%.1f s)\n", name, secs);
    }
    fflush(stdout);
    capture_end(cap, saved);
    if (shared) shared->running[worker][0] = 0;
}

void th_set_filter(const char *f)
{
    filter = f;
}

/* The parent of the workers: waits for each, names any that did not end normally and the
 * test it was running, prints the summary and exits. */
static void parent_wait(const pid_t *pids, int jobs)
{
    int broken = 0;
    for (int k = 0; k < jobs; k++) {
        int st = 0;
        if (waitpid(pids[k], &st, 0) < 0) st = -1;
        if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
            broken++;
            fflush(stdout);
            if (shared->output[k][0]) { /* what the test printed before its worker died */
                FILE *f = fopen(shared->output[k], "r");
                char buf[4096];
                for (size_t n; f && (n = fread(buf, 1, sizeof buf, f)) > 0;) write_all(buf, n);
                if (f) fclose(f);
                unlink(shared->output[k]);
            }
            printf("FAIL worker %d ended (%s %d) while running %s\n", k,
                   st != -1 && WIFSIGNALED(st) ? "signal" : "status",
                   st == -1          ? -1
                   : WIFSIGNALED(st) ? WTERMSIG(st)
                                     : WEXITSTATUS(st),
                   shared->running[k][0] ? shared->running[k] : "no test");
        }
    }
    passed = shared->passed;
    failed = shared->failed + broken;
    skipped = shared->skipped;
    for (int k = 0; k < shared->failed && k < TH_MAX_FAILED; k++)
        printf("failed: %s\n", shared->failed_names[k]);
    shared = NULL;
    exit(th_summary());
}

int th_worker(int k, int fd)
{
    Shared *s = mmap(NULL, sizeof *s, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    close(fd);
    if (s == MAP_FAILED || k < 0 || k >= TH_MAX_JOBS) return -1;
    shared = s;
    worker = k;
    return 0;
}

void th_parallel(int jobs, char **argv)
{
    if (jobs > TH_MAX_JOBS) jobs = TH_MAX_JOBS;
    if (jobs < 2 || shared) return; /* a worker runs its tests itself */
    int fd = memfd_create("vbcl-tests", 0);
    if (fd < 0 || ftruncate(fd, sizeof(Shared)) != 0) {
        perror("vbcl-tests: shared memory for the workers; running in one process");
        if (fd >= 0) close(fd);
        return;
    }
    Shared *s = mmap(NULL, sizeof *s, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (s == MAP_FAILED) {
        perror("vbcl-tests: shared memory for the workers; running in one process");
        close(fd);
        return;
    }
    int argc = 0;
    while (argv[argc]) argc++;
    char **args = calloc((size_t)argc + 4, sizeof *args);
    char ks[16], fds[16];
    pid_t pids[TH_MAX_JOBS];
    int started = 0;
    fflush(stdout);
    fflush(stderr);
    for (; args && started < jobs; started++) {
        snprintf(ks, sizeof ks, "%d", started);
        snprintf(fds, sizeof fds, "%d", fd);
        int n = 0;
        args[n++] = argv[0];
        args[n++] = "--worker";
        args[n++] = ks;
        args[n++] = fds;
        for (int i = 1; i < argc; i++) args[n++] = argv[i];
        args[n] = NULL;
        pid_t p = fork();
        if (p == 0) { /* a new program, not a copy: the libraries' threads are not forked */
            execv("/proc/self/exe", args);
            perror("vbcl-tests: exec of a worker");
            _exit(127);
        }
        if (p < 0) {
            perror("vbcl-tests: fork");
            break;
        }
        pids[started] = p;
    }
    free(args);
    close(fd);
    if (started == 0) {
        munmap(s, sizeof *s);
        return; /* no worker could start: run here */
    }
    shared = s;
    parent_wait(pids, started);
}

int th_summary(void)
{
    if (shared) return 0; /* a worker: the parent sums the shared counts */
    if (skipped)
        printf("%d passed, %d failed, %d skipped\n", passed, failed, skipped);
    else
        printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
