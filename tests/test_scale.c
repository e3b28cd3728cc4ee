/* test_scale.c — scaling out (docs/scaling.md): a frame shared among several OpenCL devices
 * (two PoCL devices, POCL_DEVICES="pthread pthread") or among MPI ranks (mpirun -np 2) is
 * the single-process image bit for bit, with per-device work in --stats-json; a failing
 * device or rank stops the run with a message naming it and writes no image; bad --device
 * lists are usage errors. */
#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "dist.h"
#include "harness.h"
#include "image_io.h"
#include "testutil.h"

/* Two CPU devices from PoCL: its pthread driver, listed twice. */
#define TWO_POCL "POCL_DEVICES='pthread pthread' "

/* Renders scene with options into tmp/name.exr (env: a prefix of variables). Returns the
 * pixels (width * height * 4, caller frees), or NULL after a failed check. */
static float *render(const char *env, const char *scene, const char *opts, const char *name, int *w,
                     int *h)
{
    char cmd[2048], out[4096], img[1024], err[256];
    snprintf(img, sizeof img, "%s/scale_%s.exr", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd, "%s%s %s -q -o %s %s", env, tu_vbcl, scene, img, opts);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "%s exited %d: %s", cmd, rc, out);
    if (rc) return NULL;
    float *px = NULL;
    if (image_read(img, w, h, &px, err, sizeof err)) {
        CHECK(0, "%s", err);
        return NULL;
    }
    return px;
}

/* How many pixels of two renders differ in any channel (bit patterns); -1 when either
 * failed or the sizes differ. */
static long differing(const float *a, const float *b, int wa, int ha, int wb, int hb)
{
    if (!a || !b || wa != wb || ha != hb) return -1;
    long n = 0;
    for (long i = 0; i < (long)wa * ha; i++) n += memcmp(a + 4 * i, b + 4 * i, 4 * sizeof *a) != 0;
    return n;
}

/* Whether PoCL gives two devices under TWO_POCL (else the tests are skipped). */
static int two_devices(void)
{
    char out[4096];
    char cmd[1024];
    snprintf(cmd, sizeof cmd, TWO_POCL "%s --list-devices", tu_vbcl);
    if (tu_run(cmd, out, sizeof out) != 0) return 0;
    return strstr(out, "\n1: ") != NULL;
}

/* The same image from one device and from two, for each kind of render: opaque, glass with
 * textures, adaptive anti-aliasing (refinement on the first device), supersampling. */
static void test_scale_devices_identical(void)
{
    if (!two_devices()) {
        th_skip("PoCL does not list two devices under POCL_DEVICES='pthread pthread'");
        return;
    }
    static const struct {
        const char *name, *scene, *opts;
    } cases[] = {
        {"quickstart", "scenes/quickstart.json", "--width 96 --height 96"},
        {"glass", "scenes/glass_bombed_sphere.json", "--width 48 --height 48 --shadow-samples 4"},
        {"aa", "tests/scenes/aa_edges.json", "--aa 0.1"},
        {"ssaa", "scenes/quickstart.json", "--width 40 --height 40 --ssaa 2"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char name[64], opts[512];
        int w1, h1, w2, h2, w3, h3;
        snprintf(name, sizeof name, "%s_one", cases[k].name);
        float *one = render(TWO_POCL, cases[k].scene, cases[k].opts, name, &w1, &h1);
        snprintf(name, sizeof name, "%s_all", cases[k].name);
        snprintf(opts, sizeof opts, "%s --device all", cases[k].opts);
        float *all = render(TWO_POCL, cases[k].scene, opts, name, &w2, &h2);
        snprintf(name, sizeof name, "%s_env", cases[k].name);
        float *env =
            render(TWO_POCL "VBCL_DEVICE=1,0 ", cases[k].scene, cases[k].opts, name, &w3, &h3);
        long d_all = differing(one, all, w1, h1, w2, h2);
        long d_env = differing(one, env, w1, h1, w3, h3);
        fprintf(stderr, "    %s: --device all: %ld, VBCL_DEVICE=1,0: %ld pixels differ\n",
                cases[k].name, d_all, d_env);
        CHECK(d_all == 0, "%s: --device all differs from one device in %ld pixels", cases[k].name,
              d_all);
        CHECK(d_env == 0, "%s: VBCL_DEVICE=1,0 differs from one device in %ld pixels",
              cases[k].name, d_env);
        free(one);
        free(all);
        free(env);
    }
}

static double json_num(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : -1.0;
}

/* Reads a --stats-json document (caller frees), or NULL after a failed check. */
static cJSON *read_json(const char *path)
{
    static char text[1 << 20];
    cJSON *doc = cJSON_Parse(tu_read_file(path, text, sizeof text));
    CHECK(doc != NULL, "%s does not parse", path);
    return doc;
}

/* Renders `args` on two PoCL devices (TWO_POCL) with --stats-json into the temporary
 * directory as NAME.png and NAME.json; returns the document (caller frees), or NULL after
 * a failed check. */
static cJSON *two_pocl_stats(const char *args, const char *name)
{
    char cmd[2048], out[4096], path[1024];
    snprintf(path, sizeof path, "%s/%s.json", tu_tmpdir(), name);
    snprintf(cmd, sizeof cmd, TWO_POCL "%s %s -q -o %s/%s.png --stats-json %s", tu_vbcl, args,
             tu_tmpdir(), name, path);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "%s exited %d: %s", cmd, rc, out);
    return rc == 0 ? read_json(path) : NULL;
}

/* --stats-json "devices": one entry per device; their tiles and rays add up to the frame's. */
static void test_scale_stats_per_device(void)
{
    if (!two_devices()) {
        th_skip("PoCL does not list two devices under POCL_DEVICES='pthread pthread'");
        return;
    }
    cJSON *doc = two_pocl_stats(
        "scenes/quickstart.json --width 64 --height 64 --aa 0.6 --device all", "scale_stats");
    if (!doc) return;
    const cJSON *devs = cJSON_GetObjectItemCaseSensitive(doc, "devices");
    const cJSON *tiles = cJSON_GetObjectItemCaseSensitive(doc, "tiles");
    const cJSON *rays = cJSON_GetObjectItemCaseSensitive(doc, "rays");
    CHECK(cJSON_GetArraySize(devs) == 2, "devices: %d entries", cJSON_GetArraySize(devs));
    /* one compilation of the scene, which both devices upload */
    const cJSON *compile = cJSON_GetObjectItemCaseSensitive(doc, "compile");
    CHECK(json_num(compile, "scenes") == 1, "two devices: %.0f scene compilations",
          json_num(compile, "scenes"));
    double sum_tiles = 0, sum_rays = 0;
    const cJSON *d;
    cJSON_ArrayForEach(d, devs)
    {
        sum_tiles += json_num(d, "tiles");
        sum_rays += json_num(d, "rays");
        fprintf(stderr, "    device %.0f: %.0f tiles, %.0f rays, busy %.1f ms\n",
                json_num(d, "index"), json_num(d, "tiles"), json_num(d, "rays"),
                json_num(d, "busy_ms"));
    }
    CHECK(sum_tiles == json_num(tiles, "count"), "device tiles %.0f, frame %.0f", sum_tiles,
          json_num(tiles, "count"));
    CHECK(sum_rays == json_num(rays, "total"), "device rays %.0f, frame %.0f", sum_rays,
          json_num(rays, "total"));
    CHECK(json_num(tiles, "count") >= 4, "a 64x64 frame on two devices: %.0f tiles",
          json_num(tiles, "count"));
    cJSON_Delete(doc);
}

/* A device list that names a device twice, an empty item or a device that does not exist:
 * exit 2, one line naming the list, nothing written. */
static void test_scale_bad_device_lists(void)
{
    static const char *bad[][2] = {
        {"0,0", "named twice"},        {"pocl,portable", "named twice"}, /* one PoCL device */
        {"0,", "separated by commas"}, {",0", "separated by commas"},
        {"0,99", "no such device 99"}, {"0,no-such-gpu", "no device name contains"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        char cmd[2048], out[4096], img[1024];
        snprintf(img, sizeof img, "%s/scale_bad.png", tu_tmpdir());
        remove(img);
        snprintf(cmd, sizeof cmd, "%s tests/scenes/tiny.json -o %s --device %s", tu_vbcl, img,
                 bad[k][0]);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 2 && strstr(out, bad[k][1]), "--device %s: exit %d, %s", bad[k][0], rc, out);
        FILE *f = fopen(img, "rb");
        CHECK(!f, "--device %s wrote %s", bad[k][0], img);
        if (f) fclose(f);
    }
}

/* Names in a device list pick among the devices the list has not named yet: with two PoCL
 * devices of the same name, "pocl,pocl" is both of them ("pocl" is in PoCL's version). */
static void test_scale_device_names(void)
{
    if (!two_devices()) {
        th_skip("PoCL does not list two devices under POCL_DEVICES='pthread pthread'");
        return;
    }
    cJSON *doc = two_pocl_stats("tests/scenes/tiny.json --device pocl,pocl", "scale_names");
    if (!doc) return;
    const cJSON *devs = cJSON_GetObjectItemCaseSensitive(doc, "devices");
    CHECK(cJSON_GetArraySize(devs) == 2 && json_num(cJSON_GetArrayItem(devs, 0), "index") == 0 &&
              json_num(cJSON_GetArrayItem(devs, 1), "index") == 1,
          "--device pocl,pocl: %d devices", cJSON_GetArraySize(devs));
    cJSON_Delete(doc);
}

/* "mpirun -np 2 --oversubscribe" (and --allow-run-as-root as root, as in CI), or NULL
 * (the test is skipped) when this build has no MPI or mpirun is missing. */
static const char *mpirun(void)
{
    if (!dist_available()) {
        th_skip("built without MPI (libopenmpi-dev: make deps)");
        return NULL;
    }
    if (tu_run("command -v mpirun", NULL, 0) != 0) {
        th_skip("mpirun not found (openmpi-bin: make deps)");
        return NULL;
    }
    /* LeakSanitizer (make test SANITIZE=...) off in the ranks: OpenMPI unloads its
     * components at MPI_Finalize, after which allocations of OpenImageIO and of the
     * unloaded modules are reported that are not vbcl's; the other checks stay on. No
     * single-copy (CMA) transfers: containers without ptrace rights refuse them. */
#define MPI_COMMON                                                                                 \
    "--oversubscribe --mca btl_vader_single_copy_mechanism none -x LSAN_OPTIONS=detect_leaks=0"
    return getuid() == 0 ? "mpirun --allow-run-as-root " MPI_COMMON : "mpirun " MPI_COMMON;
}

/* Two ranks against one process: a still image (tiles), an anti-aliased one (tiles, then
 * refinement on rank 0), a supersampled one (rank 0 alone), and 3 frames of an animation, by the
 * frame queue and, with
 * --stats-json, frame by frame in tiles. */
static void test_scale_mpi_identical(void)
{
    const char *mpi = mpirun();
    if (!mpi) return;
    static const struct {
        const char *name, *scene, *opts;
    } cases[] = {
        {"quickstart", "scenes/quickstart.json", "--width 64 --height 64"},
        {"aa", "tests/scenes/aa_edges.json", "--aa 0.1"},
        {"ssaa", "scenes/quickstart.json", "--width 40 --height 40 --ssaa 2"},
    };
    char env[256];
    snprintf(env, sizeof env, "%s -np 2 ", mpi);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char name[64];
        int w1, h1, w2, h2;
        snprintf(name, sizeof name, "mpi_%s_one", cases[k].name);
        float *one = render("", cases[k].scene, cases[k].opts, name, &w1, &h1);
        snprintf(name, sizeof name, "mpi_%s_two", cases[k].name);
        float *two = render(env, cases[k].scene, cases[k].opts, name, &w2, &h2);
        long d = differing(one, two, w1, h1, w2, h2);
        fprintf(stderr, "    %s: 2 ranks: %ld pixels differ\n", cases[k].name, d);
        CHECK(d == 0, "%s: 2 ranks differ from one process in %ld pixels", cases[k].name, d);
        free(one);
        free(two);
    }
    /* the animation: frames 0-2 of the thesis's figure A.6 (eta 1 to 3.7 over frames) */
    const char *anim = "scenes/thesis/a6_eta_animation.json --frames 0:2 --width 24 --height 24 "
                       "--shadow-samples 1";
    const char *how[3] = {"", "", "--stats-json"};
    char cmd[2048], out[8192];
    for (int run = 0; run < 3; run++) {
        char opts[256] = "";
        if (run == 2) snprintf(opts, sizeof opts, "--stats-json %s/mpi_anim.json", tu_tmpdir());
        snprintf(cmd, sizeof cmd, "%s%s %s -q -o %s/mpi_anim%d_##.exr %s", run ? env : "", tu_vbcl,
                 anim, tu_tmpdir(), run, opts);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0, "%s exited %d: %s", cmd, rc, out);
    }
    for (int run = 1; run < 3; run++)
        for (int f = 0; f < 3; f++) {
            char a[1024], b[1024], err[256];
            float *pa = NULL, *pb = NULL;
            int wa = 0, ha = 0, wb = 0, hb = 0;
            snprintf(a, sizeof a, "%s/mpi_anim0_%02d.exr", tu_tmpdir(), f);
            snprintf(b, sizeof b, "%s/mpi_anim%d_%02d.exr", tu_tmpdir(), run, f);
            if (image_read(a, &wa, &ha, &pa, err, sizeof err) ||
                image_read(b, &wb, &hb, &pb, err, sizeof err))
                CHECK(0, "%s", err);
            long d = differing(pa, pb, wa, ha, wb, hb);
            CHECK(d == 0, "animation frame %d (%s): %ld pixels differ", f,
                  run == 1 ? "frame queue" : "tiles", d);
            free(pa);
            free(pb);
        }
    fprintf(stderr, "    animation: 3 frames equal by frame queue and by tiles (%s)\n", how[2]);
    char path[1024];
    snprintf(path, sizeof path, "%s/mpi_anim.json", tu_tmpdir());
    cJSON *doc = read_json(path);
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(doc, "frames");
    CHECK(cJSON_GetArraySize(frames) == 3, "--stats-json: %d frames", cJSON_GetArraySize(frames));
    const cJSON *devs = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(frames, 0), "devices");
    double ranks = 0;
    const cJSON *dv;
    cJSON_ArrayForEach(dv, devs) ranks += json_num(dv, "rank");
    CHECK(cJSON_GetArraySize(devs) == 2 && ranks == 1, "frame 0's devices: %d, ranks sum %.0f",
          cJSON_GetArraySize(devs), ranks);
    const char *h0 = cJSON_GetStringValue(
                   cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(devs, 0), "host")),
               *h1 = cJSON_GetStringValue(
                   cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(devs, 1), "host"));
    CHECK(h0 && h1 && h0[0] && !strcmp(h0, h1), "both ranks name this host (%s, %s)",
          h0 ? h0 : "none", h1 ? h1 : "none");
    cJSON_Delete(doc);
    /* two ranks on one machine and one device: one device in the summary, two queues */
    snprintf(cmd, sizeof cmd,
             "%s%s scenes/quickstart.json --width 32 --height 32 -o %s/mpi_one.pfm", env, tu_vbcl,
             tu_tmpdir());
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "on 2 devices") && strstr(out, ", 2 queues"),
          "the summary counts one device (%d): %s", rc, out);
}

/* A device that fails on rank 1 (VBCL_FAIL_TILE, an MPMD launch) and a rank that is killed:
 * the run fails naming the rank (and the device), and no image is written. */
static void test_scale_mpi_failure(void)
{
    const char *mpi = mpirun();
    if (!mpi) return;
    char cmd[4096], out[8192], img[1024];
    snprintf(img, sizeof img, "%s/mpi_fail.png", tu_tmpdir());
    /* 1200x1200: about 6 s of tiles on the 2-core Xeon, so that rank 1 takes one even when
     * it starts seconds after rank 0 (at 400x400 rank 0 rendered the whole image in 0.7 s,
     * before a rank 1 slowed by a loaded machine had opened its device); the run ends at
     * rank 1's first tile */
    const char *scene = "scenes/quickstart.json --width 1200 --height 1200";
    remove(img);
    snprintf(cmd, sizeof cmd, "%s -np 1 %s %s -q -o %s : -np 1 env VBCL_FAIL_TILE=1 %s %s -q -o %s",
             mpi, tu_vbcl, scene, img, tu_vbcl, scene, img);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "vbcl: rank 1: device 0 (") && strstr(out, "VBCL_FAIL_TILE"),
          "a failing device on rank 1: exit %d: %s", rc, out);
    CHECK(access(img, F_OK) != 0, "%s written after a failure", img);
    /* rank 1 killed after 2 s of a render that takes far longer (16 samples per pixel: one
     * per pixel took under 2 s once the grid's leaves were tested four triangles at a time) */
    const char *slow = "scenes/glass_bombed_sphere.json --width 400 --height 400 --ssaa 4";
    remove(img);
    snprintf(cmd, sizeof cmd, "%s -np 1 %s %s -q -o %s : -np 1 timeout -s KILL 2 %s %s -q -o %s",
             mpi, tu_vbcl, slow, img, tu_vbcl, slow, img);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc != 0 && strstr(out, "rank 1"), "rank 1 killed: exit %d: %s", rc, out);
    CHECK(access(img, F_OK) != 0, "%s written after rank 1 died", img);
    /* one process with two devices: the same failure names the device */
    remove(img);
    snprintf(cmd, sizeof cmd, TWO_POCL "VBCL_FAIL_TILE=2 %s %s -q --device all -o %s", tu_vbcl,
             scene, img);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "vbcl: device ") && strstr(out, "VBCL_FAIL_TILE"),
          "a failing device of two: exit %d: %s", rc, out);
    CHECK(access(img, F_OK) != 0, "%s written after a device failed", img);
}

void suite_scale(void)
{
    RUN_TEST(test_scale_devices_identical);
    RUN_TEST(test_scale_stats_per_device);
    RUN_TEST(test_scale_bad_device_lists);
    RUN_TEST(test_scale_device_names);
    RUN_TEST(test_scale_mpi_identical);
    RUN_TEST(test_scale_mpi_failure);
}
