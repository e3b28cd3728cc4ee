/* test_structure.c — the layout rules of docs/architecture.md ("The host's layers"), checked
 * by scripts/check_structure.py: no include cycle among host modules, no function in host/
 * or kernels/ over 80 lines without a reason written above it. The checker is first shown
 * to catch both on a small tree of its own. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

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

/* A tree with two modules in two folders that include each other's headers and a 91-line
 * function, then without the cycle and with the function's reason stated. */
static void test_structure_checker_catches(void)
{
    char root[1024], x[1100], y[1100], cmd[2300], out[8192], body[4096] = "int f(void)\n{\n";
    snprintf(root, sizeof root, "%s/structure", tu_tmpdir());
    snprintf(x, sizeof x, "%s/host", root);
    mkdir(root, 0755);
    mkdir(x, 0755);
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
              strstr(out, "f is 91 lines"),
          "the checker finds both cycles and the long function (exit %d): %s", rc, out);
    write_in(y, "b.h", "/* no includes */\n");
    char reasoned[4200] = "/* Long: one piece, as the test wants it. */\n";
    strcat(reasoned, body);
    write_in(x, "a.c", reasoned);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "a long function with a stated reason and no cycle pass (exit %d): %s", rc, out);
}

/* The project itself. */
static void test_structure_of_the_project(void)
{
    char out[16384];
    int rc = tu_run("python3 scripts/check_structure.py .", out, sizeof out);
    fprintf(stderr, "    %s", out);
    CHECK(rc == 0, "scripts/check_structure.py (exit %d):\n%s", rc, out);
}

void suite_structure(void)
{
    RUN_TEST(test_structure_checker_catches);
    RUN_TEST(test_structure_of_the_project);
}
