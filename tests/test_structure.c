/* test_structure.c — the layout rules of docs/architecture.md ("The host's layers"), checked
 * by scripts/check_structure.py: no include cycle among host modules, each folder's includes
 * only from the folders its row of the layers' table uses, no function in host/ or kernels/
 * over 80 lines without a reason written above it. The checker is first shown to catch each
 * on a small tree of its own. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "testutil.h"

/* Writes text to dir/name. */
static void write_in(const char *dir, const char *name, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL, "cannot write %s", path);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

/* A tree whose layers' table has host/x use host/y, with two modules in the two folders that
 * include each other's headers and a 91-line function; then without the cycle and with the
 * function's reason stated; then with host/y's row gone from the table. */
static void test_structure_checker_catches(void)
{
    char root[1024], x[1100], y[1100], docs[1100], cmd[2300], out[8192];
    char body[4096] = "int f(void)\n{\n";
    const char *table = "### The host's layers\n\n| folder | what | uses |\n|---|---|---|\n"
                        "| `host/x/` | above | y |\n";
    char layers[256];
    snprintf(layers, sizeof layers, "%s| `host/y/` | below | — |\n", table);
    snprintf(root, sizeof root, "%s/structure", tu_tmpdir());
    snprintf(x, sizeof x, "%s/host", root);
    snprintf(docs, sizeof docs, "%s/docs", root);
    mkdir(root, 0755);
    mkdir(x, 0755);
    mkdir(docs, 0755);
    write_in(docs, "architecture.md", layers);
    snprintf(x, sizeof x, "%s/host/x", root);
    snprintf(y, sizeof y, "%s/host/y", root);
    mkdir(x, 0755);
    mkdir(y, 0755);
    for (int i = 0; i < 88; i++) strcat(body, "    ;\n");
    strcat(body, "}\n");
    write_in(x, "a.h", "#include \"b.h\"\n");
    write_in(y, "b.h", "#include \"a.h\"\n");
    write_in(x, "a.c", body);
    write_in(y, "b.c", "#include \"b.h\"\n");
    snprintf(cmd, sizeof cmd, "python3 scripts/check_structure.py %s", root);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "include cycle among host folders: host/x <-> host/y") &&
              strstr(out, "include cycle among host modules: host/x/a <-> host/y/b") &&
              strstr(out, "host/y/b.h includes a.h (host/x/a.h): host/y uses no other folder, "
                          "not host/x") &&
              strstr(out, "f is 91 lines"),
          "the checker finds both cycles, the include against the table and the long function "
          "(exit %d): %s",
          rc, out);
    write_in(y, "b.h", "/* no includes */\n");
    char reasoned[4200] = "/* Long: one piece, as the test wants it. */\n";
    strcat(reasoned, body);
    write_in(x, "a.c", reasoned);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "a long function with a stated reason and no cycle pass (exit %d): %s", rc, out);
    write_in(docs, "architecture.md", table);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "host/y: no row in the table"),
          "a folder with no row in the table fails (exit %d): %s", rc, out);
}

/* The project itself. */
static void test_structure_of_the_project(void)
{
    char out[16384];
    int rc = tu_run("python3 scripts/check_structure.py .", out, sizeof out);
    fprintf(stderr, "    %s", out);
    CHECK(rc == 0, "scripts/check_structure.py (exit %d):\n%s", rc, out);
}

/* Sorts the "ok/FAIL/skip NAME" lines of a run's output, times cut off, into out. */
static void result_lines(const char *text, char *out, size_t n)
{
    char lines[64][128];
    int k = 0;
    for (const char *p = text; *p && k < 64;) {
        const char *e = strchr(p, '\n');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (!strncmp(p, "ok   ", 5) || !strncmp(p, "FAIL ", 5) || !strncmp(p, "skip ", 5)) {
            const char *t = memchr(p, '(', len);
            snprintf(lines[k++], sizeof lines[0], "%.*s", (int)((t ? t : p + len) - p), p);
        }
        p += len + (e != NULL);
    }
    qsort(lines, (size_t)k, sizeof lines[0], (int (*)(const void *, const void *))strcmp);
    out[0] = 0;
    for (int i = 0; i < k; i++) snprintf(out + strlen(out), n - strlen(out), "%s\n", lines[i]);
}

/* The last line of a run's output (its summary) into out. */
static void last_line(const char *text, char *out, size_t n)
{
    size_t len = strlen(text);
    while (len > 0 && text[len - 1] == '\n') len--;
    size_t start = len;
    while (start > 0 && text[start - 1] != '\n') start--;
    snprintf(out, n, "%.*s", (int)(len - start), text + start);
}

/* vbcl-tests -j 2 runs the same tests as one process, each once, with the same summary. */
static void test_harness_workers(void)
{
    static char one[16384], two[16384];
    char a[4096], b[4096], sa[128], sb[128], self[1024], cmd[2400];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    CHECK(n > 0, "cannot read /proc/self/exe");
    if (n <= 0) return;
    self[n] = 0;
    snprintf(cmd, sizeof cmd, "'%s' --vbcl '%s' mesh", self, tu_vbcl);
    int rc1 = tu_run(cmd, one, sizeof one);
    snprintf(cmd, sizeof cmd, "'%s' --vbcl '%s' -j 2 mesh", self, tu_vbcl);
    int rc2 = tu_run(cmd, two, sizeof two);
    result_lines(one, a, sizeof a);
    result_lines(two, b, sizeof b);
    last_line(one, sa, sizeof sa);
    last_line(two, sb, sizeof sb);
    CHECK(rc1 == 0 && rc2 == 0 && a[0] && !strcmp(a, b) && strstr(sa, " passed, 0 failed") &&
              !strcmp(sa, sb),
          "one process (exit %d):\n%s\ntwo workers (exit %d):\n%s", rc1, one, rc2, two);
}

void suite_structure(void)
{
    RUN_TEST(test_harness_workers);
    RUN_TEST(test_structure_checker_catches);
    RUN_TEST(test_structure_of_the_project);
}
