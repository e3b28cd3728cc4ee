/* stress_main.c — vbcl-stress (`make stress`): at least 10^7 rays aimed at the edges and
 * vertices of closed meshes at scales 1e-6 to 1e6 and up to 1e5 from the origin, counting
 * leaks, self-hits and origins in the wrong medium; the scenes of tests/scenes/frame/ at
 * every decade of scale and moved up to 1e5 (scripts/frame_check.py --stress); then an
 * 8192x8192 render checked for non-finite pixels. Usage: vbcl-stress [--vbcl PATH]
 * [--targets-per-case N] [--only SHAPE] [--no-rays] [--no-frame] [--no-big]: --only runs the
 * ray cases of the shapes and texture meshes whose name contains SHAPE. */
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
    unsigned long long far_aimed, far_leaks; /* the cases far from the scene's frame */
} Totals;

static void run_case(VbDevice *d, const char *name, const char *object, int convex, const WtCase *c,
                     long targets, unsigned seed, Totals *tot)
{
    char json[4096], err[1024], path[] = "/tmp/vbcl-stress-XXXXXX.json";
    watertight_scene_json(object, c->scale, c->offset, c->look_origin, json, sizeof json);
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
    int brute_every = getenv("VBCL_WT_BRUTE_EVERY") ? atoi(getenv("VBCL_WT_BRUTE_EVERY")) : 64;
    int rc = watertight_run(d, path, convex, targets, seed, brute_every, &one, err, sizeof err);
    remove(path);
    tot->cases++;
    const char *where = c->label;
    if (rc) {
        printf("  %-16s scale %-6g %-9s ERROR %s\n", name, c->scale, where, err);
        tot->failed_cases++;
        return;
    }
    unsigned long long rays = one.aimed + one.brute_aimed + one.offset_rays;
    int bad = one.escapes_unexplained != 0;
    printf("  %-16s scale %-6g %-9s %9llu rays: leaks %llu (brute %llu/%llu), self-hits %llu, "
           "origins in the wrong medium %llu in / %llu out (%llu unexplained)%s, %.2f Mrays/s\n",
           name, c->scale, where, rays, one.leaks, one.brute_leaks, one.brute_aimed, one.self_hits,
           one.escapes, one.escapes_out, one.escapes_unexplained, bad ? " FAILED" : "",
           one.seconds > 0 ? rays / one.seconds * 1e-6 : 0.0);
    tot->failed_cases += bad;
    fflush(stdout);
    WtStats *t = &tot->st;
    /* far from the frame the grid's cells are a few hundred units in the last place of
     * their coordinates, and a walk may miss a hit there (brute force does not): counted
     * apart, not asserted (docs/testing.md, "Known failures") */
    if (c->look_origin)
        tot->far_aimed += one.aimed, tot->far_leaks += one.leaks;
    else
        t->aimed += one.aimed, t->leaks += one.leaks;
    t->brute_aimed += one.brute_aimed;
    t->camera_aimed += one.camera_aimed;
    t->brute_leaks += one.brute_leaks, t->offset_rays += one.offset_rays;
    t->self_hits += one.self_hits, t->escapes += one.escapes, t->escapes_out += one.escapes_out;
    t->escapes_unexplained += one.escapes_unexplained, t->other_piece += one.other_piece;
    t->grazing += one.grazing;
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

/* Runs scripts/frame_check.py --stress with vbcl: the scenes of tests/scenes/frame/ scaled
 * and moved, each against its unit render (RMS, largest difference, ray-tree counters,
 * work). Returns 0 when every case is within its bounds. */
static int frame_cases(const char *vbcl)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "python3 scripts/frame_check.py --stress --vbcl %s", vbcl);
    printf("scenes scaled and moved: %s\n", cmd);
    fflush(stdout);
    double t0 = clu_now_ms();
    int st = system(cmd);
    int ok = st != -1 && WIFEXITED(st) && WEXITSTATUS(st) == 0;
    printf("scenes scaled and moved: %s in %.1f s\n", ok ? "ok" : "FAILED",
           (clu_now_ms() - t0) * 1e-3);
    return ok ? 0 : -1;
}

/* The bound on origins in the wrong medium, per million offset rays (docs/testing.md,
 * "Origins in the wrong medium"): every one of them is an offset that carried its origin
 * across the plane of a neighbour at a sharp or concave edge the targets sit on, within
 * the offset's length, and their number follows that length. */
#define WRONG_MEDIUM_PPM 15000.0

/* Every shape in every watertight_case, and the texture meshes under scenes/textures/ moved
 * at each scale and far from the origin; prints the totals. Returns 0 when nothing leaked, hit
 * itself or landed in the wrong medium beyond what the offset explains and the bound. */
static int ray_cases(VbDevice *d, long targets, const char *only)
{
    Totals tot;
    memset(&tot, 0, sizeof tot);
    double t0 = clu_now_ms();
    /* seeds by shape and case, so that --only fires the same rays */
    for (int i = 0; i < watertight_nshapes; i++)
        for (int k = 0; k < WT_NCASES; k++) {
            WtCase c;
            watertight_case(k, &c);
            if (!watertight_case_fits(&watertight_shapes[i], &c)) continue;
            if (only && !strstr(watertight_shapes[i].name, only)) continue;
            run_case(d, watertight_shapes[i].name, watertight_shapes[i].json,
                     watertight_shapes[i].convex, &c, targets, (unsigned)(1000 + i * WT_NCASES + k),
                     &tot);
        }
    static char meshes[MAX_MESHES][1024];
    int nmeshes = texture_meshes(meshes, MAX_MESHES);
    for (int i = 0; i < nmeshes; i++) {
        char object[1200];
        snprintf(object, sizeof object, "\"shape\": \"mesh\", \"file\": \"%s\"", meshes[i]);
        const char *base = strrchr(meshes[i], '/') + 1;
        if (only && !strstr(base, only)) continue;
        for (int k = 1; k < WT_NCASES; k += 2) { /* moved at each scale, and 1e4 away */
            WtCase c;
            watertight_case(k, &c);
            run_case(d, base, object, 0, &c, targets / 4, (unsigned)(5000 + i * WT_NCASES + k),
                     &tot);
        }
    }
    double wall = (clu_now_ms() - t0) * 1e-3;
    WtStats *s = &tot.st;
    unsigned long long rays = s->aimed + s->brute_aimed + s->offset_rays;
    printf("total: %d cases (%d texture meshes), %llu rays in %.1f s (%.2f Mrays/s traced, "
           "%.2f Mrays/s with the host checks)\n",
           tot.cases, nmeshes, rays, wall, s->seconds > 0 ? rays / s->seconds * 1e-6 : 0.0,
           rays / wall * 1e-6);
    printf("leaks: %llu of %llu aimed rays in the scene's frame, %llu of them camera rays (brute "
           "force: %llu of %llu); %llu targets skipped; far from the frame %llu of %llu (not "
           "asserted)\n",
           s->leaks, s->aimed, s->camera_aimed, s->brute_leaks, s->brute_aimed, s->skipped,
           tot.far_leaks, tot.far_aimed);
    double ppm = s->offset_rays ? 1e6 * (double)(s->escapes + s->escapes_out) / s->offset_rays : 0;
    int wrong = ppm > WRONG_MEDIUM_PPM || s->escapes_unexplained;
    printf("self-hits: %llu of %llu offset rays; origins in the wrong medium: %llu leaving "
           "inward, %llu outward, %.0f per million offset rays (at most %.0f), %llu not explained "
           "by the offset (none allowed)%s; not checked: %llu first hits on another piece of a "
           "texture, %llu along the hit triangle's plane\n",
           s->self_hits, s->offset_rays, s->escapes, s->escapes_out, ppm, WRONG_MEDIUM_PPM,
           s->escapes_unexplained, wrong ? ": FAILED" : "", s->other_piece, s->grazing);
    return tot.failed_cases || s->leaks || s->brute_leaks || s->self_hits || wrong ? -1 : 0;
}

int main(int argc, char **argv)
{
    const char *vbcl = "./vbcl";
    long targets = 100000;
    int big = 1, rays = 1, frame = 1;
    const char *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--vbcl") && i + 1 < argc)
            vbcl = argv[++i];
        else if (!strcmp(argv[i], "--targets-per-case") && i + 1 < argc)
            targets = atol(argv[++i]);
        else if (!strcmp(argv[i], "--no-big"))
            big = 0;
        else if (!strcmp(argv[i], "--no-rays"))
            rays = 0;
        else if (!strcmp(argv[i], "--no-frame"))
            frame = 0;
        else if (!strcmp(argv[i], "--only") && i + 1 < argc)
            only = argv[++i];
        else {
            fprintf(stderr,
                    "usage: vbcl-stress [--vbcl PATH] [--targets-per-case N] [--only SHAPE] "
                    "[--no-rays] [--no-frame] [--no-big]\n");
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
    int bad = 0;
    if (rays && ray_cases(&d, targets, only)) bad = 1;
    clu_device_close(&d);
    if (frame && frame_cases(vbcl)) bad = 1;
    if (big && render_big(vbcl)) bad = 1;
    printf("%s\n", bad ? "vbcl-stress: FAILED" : "vbcl-stress: ok");
    return bad ? 1 : 0;
}
