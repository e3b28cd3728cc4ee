/* test_main.c — runs every suite; usage: vbcl-tests [--vbcl PATH] [-j JOBS] [NAME-FILTER]. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"
#include "scene.h"
#include "texgen.h"
#include "testutil.h"

const char *tu_vbcl = "./vbcl";
static VbDevice device;
static int device_state; /* 0 untried, 1 open, -1 failed */
static char tmpdir[256];

VbDevice *tu_device(void)
{
    if (device_state == 0) {
        char err[512];
        if (clu_device_open(NULL, &device, err, sizeof err)) {
            fprintf(stderr, "    no OpenCL device: %s\n", err);
            device_state = -1;
        } else {
            device_state = 1;
        }
    }
    return device_state == 1 ? &device : NULL;
}

int tu_run(const char *cmd, char *out, size_t outlen)
{
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    if (!p) return -1;
    size_t n = 0;
    char buf[4096];
    size_t got;
    while ((got = fread(buf, 1, sizeof buf, p)) > 0) {
        if (out && n + 1 < outlen) {
            size_t k = got < outlen - 1 - n ? got : outlen - 1 - n;
            memcpy(out + n, buf, k);
            n += k;
        }
    }
    if (out && outlen) out[n] = 0;
    int st = pclose(p);
    if (st == -1) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

char *tu_read_file(const char *path, char *buf, size_t n)
{
    FILE *f = fopen(path, "rb");
    size_t got = f && n > 0 ? fread(buf, 1, n - 1, f) : 0;
    if (f) fclose(f);
    if (n > 0) buf[got] = 0;
    return buf;
}

void tu_expect_refused(const char *scene_path, const char *args, const char *needle)
{
    char img[512], cmd[4096], out[8192], buf[64];
    snprintf(img, sizeof img, "%s/keep.png", tu_tmpdir());
    FILE *f = fopen(img, "w");
    if (f) {
        fputs("previous image", f);
        fclose(f);
    }
    /* a hang fails (124) */
    snprintf(cmd, sizeof cmd, "timeout 300 %s %s -o %s %s", tu_vbcl, scene_path, img, args);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 2, "%s: exit 2 for bad input (got %d): %s", args, rc, out);
    CHECK(strstr(out, needle) != NULL, "%s: the message \"%s\" names \"%s\"", args, out, needle);
    char *nl = strchr(out, '\n');
    CHECK(nl && nl[1] == 0, "%s: exactly one line: %s", args, out);
    CHECK(strcmp(tu_read_file(img, buf, sizeof buf), "previous image") == 0,
          "%s: existing output untouched", args);
}

int tu_dir_has(const char *dir, const char *part)
{
    DIR *d = opendir(dir);
    int found = 0;
    for (struct dirent *e; d && (e = readdir(d));) found |= strstr(e->d_name, part) != NULL;
    if (d) closedir(d);
    return found;
}

const char *tu_tmpdir(void)
{
    if (!tmpdir[0]) {
        snprintf(tmpdir, sizeof tmpdir, "/tmp/vbcl-tests-XXXXXX");
        if (!mkdtemp(tmpdir)) {
            perror("mkdtemp");
            exit(1);
        }
    }
    return tmpdir;
}

const char *tu_write_file(const char *name, const char *text)
{
    static char ring[8][512];
    static int next;
    char *path = ring[next++ % 8];
    snprintf(path, sizeof ring[0], "%s/%s", tu_tmpdir(), name);
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
    return path;
}

static void cleanup(void)
{
    if (tmpdir[0]) {
        char cmd[512];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
        if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    }
    if (device_state == 1) clu_device_close(&device);
}

int main(int argc, char **argv)
{
    int jobs = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--vbcl") && i + 1 < argc)
            tu_vbcl = argv[++i];
        else if (!strcmp(argv[i], "-j") && i + 1 < argc)
            jobs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--worker") && i + 2 < argc) {
            if (th_worker(atoi(argv[i + 1]), atoi(argv[i + 2]))) {
                fprintf(stderr, "vbcl-tests: --worker %s %s: no shared counts\n", argv[i + 1],
                        argv[i + 2]);
                return 2;
            }
            i += 2;
        } else
            th_set_filter(argv[i]);
    }
    th_parallel(jobs, argv);
    atexit(cleanup);
    suite_kernels(); /* first: its probe kernels are the longest compile of a cold run */
    suite_mesh();
    suite_grid_build();
    suite_scene();
    suite_objects();
    suite_texgen();
    suite_cli();
    suite_optics();
    suite_patterns();
    suite_environment();
    suite_stability();
    suite_render();
    suite_aa();
    suite_aa_map();
    suite_dispersion();
    suite_structure();
    suite_scale();
    suite_faults();
    suite_frame();
    suite_crop();
    return th_summary();
}
