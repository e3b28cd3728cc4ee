/* stress_main.c — vbcl-stress (`make stress`): at least 10^7 rays aimed at the edges and
 * vertices of closed meshes at scales 1e-3, 1 and 1e4, counting leaks and self-hits, then
 * an 8192x8192 render checked for non-finite pixels. Usage: vbcl-stress [--vbcl PATH]
 * [--targets-per-case N] [--no-big]. */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "clu.h"
#include "image_io.h"
#include "watertight.h"

#define TEXTURE_DIR "scenes/textures"
#define MAX_MESHES  32

typedef struct Totals {
    WtStats st;
    int cases, failed_cases;
} Totals;

static void run_case(VbDevice *d, const char *name, const char *object, int convex, double scale,
                     int moved, long targets, unsigned seed, Totals *tot)
{
    double off[3] = {moved * 50 * scale, moved * -30 * scale, moved * 40 * scale};
    char json[4096], err[1024], path[] = "/tmp/vbcl-stress-XXXXXX.json";
    watertight_scene_json(object, scale, off, json, sizeof json);
    int fd = mkstemps(path, 5);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        fprintf(stderr, "vbcl-stress: cannot write a temporary scene\n");
        tot->failed_cases++;
        return;
    }
    fputs(json, f);
    fclose(f);
    WtStats one;
    memset(&one, 0, sizeof one);
    int brute_every = 64;
    int rc = watertight_run(d, path, convex, targets, seed, brute_every, &one, err, sizeof err);
    remove(path);
    tot->cases++;
    if (rc) {
        printf("  %-16s scale %-6g %-5s ERROR %s\n", name, scale, moved ? "moved" : "", err);
        tot->failed_cases++;
        return;
    }
    unsigned long long rays = one.aimed + one.brute_aimed + one.offset_rays;
    printf("  %-16s scale %-6g %-5s %9llu rays: leaks %llu (brute %llu/%llu), self-hits %llu, "
           "origins in the wrong medium %llu in / %llu out, %.2f Mrays/s\n",
           name, scale, moved ? "moved" : "", rays, one.leaks, one.brute_leaks, one.brute_aimed,
           one.self_hits, one.escapes, one.escapes_out,
           one.seconds > 0 ? rays / one.seconds * 1e-6 : 0.0);
    fflush(stdout);
    WtStats *t = &tot->st;
    t->aimed += one.aimed, t->leaks += one.leaks, t->brute_aimed += one.brute_aimed;
    t->camera_aimed += one.camera_aimed;
    t->brute_leaks += one.brute_leaks, t->offset_rays += one.offset_rays;
    t->self_hits += one.self_hits, t->escapes += one.escapes, t->escapes_out += one.escapes_out;
    t->skipped += one.skipped, t->seconds += one.seconds;
}

/* Closed meshes written by `vbcl texgen` under scenes/textures/, if any (absolute paths). */
static int texture_meshes(char paths[][1024], int max)
{
    DIR *dir = opendir(TEXTURE_DIR);
    if (!dir) return 0;
    char cwd[512];
    if (!getcwd(cwd, sizeof cwd)) cwd[0] = 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(dir)) && n < max) {
        const char *dot = strrchr(e->d_name, '.');
        if (dot && (!strcmp(dot, ".obj") || !strcmp(dot, ".ply")))
            snprintf(paths[n++], 1024, "%s/%s/%s", cwd, TEXTURE_DIR, e->d_name);
    }
    closedir(dir);
    return n;
}

/* Renders tests/scenes/stress/big_8192.json and checks every pixel; reports time and the
 * child's peak memory. */
static int render_big(const char *vbcl)
{
    char cmd[2048], img[] = "/tmp/vbcl-stress-big-XXXXXX.exr";
    int fd = mkstemps(img, 4);
    if (fd < 0) return -1;
    snprintf(cmd, sizeof cmd, "%s tests/scenes/stress/big_8192.json -q -o %s", vbcl, img);
    double t0 = clu_now_ms();
    int st = system(cmd);
    double secs = (clu_now_ms() - t0) * 1e-3;
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    int ok = st != -1 && WIFEXITED(st) && WEXITSTATUS(st) == 0;
    long bad = -1;
    int w = 0, h = 0;
    if (ok) {
        float *px = NULL;
        char err[512];
        if (image_read(img, &w, &h, &px, err, sizeof err) == 0) {
            bad = 0;
            for (long i = 0; i < 4L * w * h; i++)
                if (i % 4 != 3) bad += !isfinite(px[i]) || px[i] < 0.0f;
            free(px);
        } else {
            fprintf(stderr, "vbcl-stress: %s\n", err);
        }
    }
    remove(img);
    printf("8192x8192 render: %s in %.1f s, peak memory %.0f MiB, %dx%d, %ld non-finite or "
           "negative values\n",
           ok ? "done" : "FAILED", secs, ru.ru_maxrss / 1024.0, w, h, bad);
    close(fd);
    return ok && bad == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *vbcl = "./vbcl";
    long targets = 100000;
    int big = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--vbcl") && i + 1 < argc)
            vbcl = argv[++i];
        else if (!strcmp(argv[i], "--targets-per-case") && i + 1 < argc)
            targets = atol(argv[++i]);
        else if (!strcmp(argv[i], "--no-big"))
            big = 0;
        else {
            fprintf(stderr, "usage: vbcl-stress [--vbcl PATH] [--targets-per-case N] [--no-big]\n");
            return 2;
        }
    }
    VbDevice d;
    char err[512];
    if (clu_device_open(NULL, &d, err, sizeof err)) {
        fprintf(stderr, "vbcl-stress: no OpenCL device: %s\n", err);
        return 1;
    }
    printf("vbcl-stress on %s: %ld targets per case\n", d.name, targets);
    static const double scales[] = {1e-3, 1.0, 1e4};
    Totals tot;
    memset(&tot, 0, sizeof tot);
    double t0 = clu_now_ms();
    unsigned seed = 1000;
    for (int i = 0; i < watertight_nshapes; i++)
        for (int k = 0; k < 3; k++)
            for (int moved = 0; moved < 2; moved++)
                run_case(&d, watertight_shapes[i].name, watertight_shapes[i].json,
                         watertight_shapes[i].convex, scales[k], moved, targets, seed++, &tot);
    static char meshes[MAX_MESHES][1024];
    int nmeshes = texture_meshes(meshes, MAX_MESHES);
    for (int i = 0; i < nmeshes; i++) {
        char object[1200];
        snprintf(object, sizeof object, "\"shape\": \"mesh\", \"file\": \"%s\"", meshes[i]);
        const char *base = strrchr(meshes[i], '/') + 1;
        for (int k = 0; k < 3; k++)
            run_case(&d, base, object, 0, scales[k], 1, targets / 4, seed++, &tot);
    }
    double wall = (clu_now_ms() - t0) * 1e-3;
    WtStats *s = &tot.st;
    unsigned long long rays = s->aimed + s->brute_aimed + s->offset_rays;
    printf("total: %d cases (%d texture meshes), %llu rays in %.1f s (%.2f Mrays/s traced, "
           "%.2f Mrays/s with the host checks)\n",
           tot.cases, nmeshes, rays, wall, s->seconds > 0 ? rays / s->seconds * 1e-6 : 0.0,
           rays / wall * 1e-6);
    printf("leaks: %llu of %llu aimed rays, %llu of them camera rays (brute force: %llu of %llu); "
           "%llu targets skipped\n",
           s->leaks, s->aimed, s->camera_aimed, s->brute_leaks, s->brute_aimed, s->skipped);
    printf("self-hits: %llu of %llu offset rays; origins in the wrong medium: %llu leaving "
           "inward, %llu outward\n",
           s->self_hits, s->offset_rays, s->escapes, s->escapes_out);
    int bad = tot.failed_cases || s->leaks || s->brute_leaks || s->self_hits;
    if (big && render_big(vbcl)) bad = 1;
    clu_device_close(&d);
    printf("%s\n", bad ? "vbcl-stress: FAILED" : "vbcl-stress: ok");
    return bad ? 1 : 0;
}
