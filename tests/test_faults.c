/* test_faults.c — faults while vbcl writes its outputs: a file-size limit, a full disk, a
 * failing sync, a signal during the write. Each must leave an older file at the path as it
 * was and no temporary beside it, exit non-zero, and name the file and the cause. And a
 * damaged cache entry, which must be named and made again (docs/testing.md, "Faults"). */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"
#include "image_io.h"
#include "testutil.h"

#define FAULT_SCENE                                                                                \
    "{\"image\": {\"width\": 96, \"height\": 96},\n"                                               \
    " \"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0]},\n"                                 \
    " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 0.5, \"flux\": 500}],\n"                    \
    " \"materials\": {\"m\": {\"diffuse\": [0.8, 0.3, 0.2]}},\n"                                   \
    " \"objects\": [{\"shape\": \"sphere\", \"material\": \"m\"}]}\n"

/* The old file every case puts at the path first: it must be there, the same, after. */
#define OLD_TEXT "an older output, kept whole\n"

/* Puts OLD_TEXT at path. */
static void put_old(const char *path)
{
    FILE *f = fopen(path, "wb");
    if (f) {
        fputs(OLD_TEXT, f);
        fclose(f);
    }
}

/* Whether path still holds OLD_TEXT, whole. */
static int old_intact(const char *path)
{
    char buf[256];
    return strcmp(tu_read_file(path, buf, sizeof buf), OLD_TEXT) == 0;
}

/* A directory of its own under the test directory (made empty). */
static const char *fault_dir(const char *name)
{
    static char dir[4][512];
    static int next;
    char *d = dir[next++ % 4];
    snprintf(d, sizeof dir[0], "%s/%s", tu_tmpdir(), name);
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", d, d);
    tu_run(cmd, NULL, 0);
    return d;
}

/* The outputs each case writes over an old file: the image in every format vbcl writes,
 * and the --stats-json document (with an 8 x 8 PFM image, which fits every limit here). */
static const char *const outputs[] = {"png", "exr", "tif", "jpg", "pfm", "json"};

/* vbcl's arguments writing the output of kind ext to dir/out.EXT. */
static void output_args(const char *scene, const char *dir, const char *ext, char *args, size_t n)
{
    if (!strcmp(ext, "json"))
        snprintf(args, n, "%s -q --width 8 --height 8 -o %s/img.pfm --stats-json %s/out.json",
                 scene, dir, dir);
    else
        snprintf(args, n, "%s -q -o %s/out.%s", scene, dir, ext);
}

/* A limit on the size of files (ulimit -f 4096: 4 MiB, which the OpenCL compiler's own
 * files fit): a 640 x 640 PFM (4.9 MB) fails with EFBIG. vbcl must not die of SIGXFSZ
 * mid-write (vbcl texgen did, writing its PNG through OpenImageIO). */
static void test_faults_file_size_limit(void)
{
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("fsize");
    char args[2048], cmd[4096], out[4096], path[1024];
    snprintf(path, sizeof path, "%s/out.pfm", dir);
    snprintf(args, sizeof args, "%s -q --width 640 --height 640 -o %s", scene, path);
    snprintf(cmd, sizeof cmd, "%s %s", tu_vbcl, args); /* unlimited first: the caches warm */
    CHECK(tu_run(cmd, out, sizeof out) == 0, "without a limit: %s", out);
    put_old(path);
    snprintf(cmd, sizeof cmd, "bash -c 'ulimit -f 4096; exec %s %s'", tu_vbcl, args);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, path) && strstr(out, "File too large"),
          "over the file-size limit: exit 1 naming the file and the cause (%d): %s", rc, out);
    CHECK(old_intact(path), "the older file is intact");
    CHECK(!tu_dir_has(dir, ".tmp"), "no temporary left");
    /* vbcl texgen opens no OpenCL device: a limit of 8 KiB, and its images (every format,
     * 15 - 210 KB at 256 x 256) and meshes (440 KB) */
    static const char *const texgen[] = {
        "fourier --pixels 256 -o %s/tex.png", "fourier --pixels 256 -o %s/tex.exr",
        "fourier --pixels 256 -o %s/tex.tif", "fourier --pixels 256 -o %s/tex.jpg",
        "bomb --count 20 -o %s/tex.obj",      "bomb --count 20 -o %s/tex.ply"};
    for (size_t i = 0; i < sizeof texgen / sizeof texgen[0]; i++) {
        char targs[1024];
        snprintf(targs, sizeof targs, texgen[i], dir);
        snprintf(path, sizeof path, "%s", strstr(targs, "-o ") + 3);
        put_old(path);
        snprintf(cmd, sizeof cmd, "bash -c 'ulimit -f 8; exec %s texgen %s'", tu_vbcl, targs);
        rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 1 && strstr(out, path) && strstr(out, "File too large"),
              "texgen %s over the limit: exit 1 naming the file and the cause (%d): %s", targs, rc,
              out);
        CHECK(old_intact(path), "texgen %s: the older file is intact", targs);
        CHECK(!tu_dir_has(dir, ".tmp"), "texgen %s: no temporary left", targs);
    }
}

/* A memory limit (ulimit -v, 1.1 GiB) that the render of a 512 x 512 image leaves room in,
 * but not anti-aliasing's trees for every pixel (--aa-min-level 1: 1.4 GiB): exit 1 with one
 * line naming what ran out and what would take less, the older image whole (before: PoCL
 * failed an assertion at the buffer's first use, SIGABRT). */
static void test_faults_memory_limit(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
#ifdef __SANITIZE_ADDRESS__
    th_skip("AddressSanitizer's shadow memory alone is beyond any such limit");
    return;
#endif
    const char *dir = fault_dir("vmem");
    char args[2048], cmd[4096], out[4096], path[1024];
    snprintf(path, sizeof path, "%s/out.png", dir);
    snprintf(args, sizeof args,
             "tests/scenes/aa_edges.json -q --width 512 --height 512 --aa 0.1 -o %s", path);
    snprintf(cmd, sizeof cmd, "bash -c 'ulimit -v 1200000; exec %s %s'", tu_vbcl, args);
    CHECK(tu_run(cmd, out, sizeof out) == 0, "the render alone fits the limit: %s", out);
    put_old(path);
    snprintf(cmd, sizeof cmd, "bash -c 'ulimit -v 1200000; exec %s %s --aa-min-level 1'", tu_vbcl,
             args);
    int rc = tu_run(cmd, out, sizeof out);
    char *nl = strchr(out, '\n');
    CHECK(rc == 1 && strstr(out, "out of memory for anti-aliasing's trees") &&
              strstr(out, "--aa-min-level") && nl && nl[1] == 0,
          "trees over the memory limit: exit 1, one line naming them and what takes less (%d): %s",
          rc, out);
    CHECK(old_intact(path), "the older image is intact");
    CHECK(!tu_dir_has(dir, ".tmp"), "no temporary left");
}

/* A small stack limit (ulimit -s): 256 KiB overflowed PoCL's threads, which glibc sizes by
 * it, in a kernel's work-group function (SIGSEGV): vbcl now gives its threads 8 MiB and
 * renders; a soft limit of 64 KiB under an unlimited hard one is raised (vbcl runs itself
 * again); a hard limit of 96 KiB, too small for its main thread, is a message and exit 1. */
static void test_faults_small_stack(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
#ifdef __SANITIZE_ADDRESS__
    th_skip("AddressSanitizer's own stack use differs");
    return;
#endif
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("stack");
    char cmd[4096], out[4096], path[1024];
    snprintf(path, sizeof path, "%s/out.pfm", dir);
    static const char *const limits[] = {"ulimit -s 256", "ulimit -S -s 64", "ulimit -s 96"};
    for (int k = 0; k < 3; k++) {
        put_old(path);
        snprintf(cmd, sizeof cmd, "bash -c '%s; exec %s %s -q --width 96 --height 96 -o %s'",
                 limits[k], tu_vbcl, scene, path);
        int rc = tu_run(cmd, out, sizeof out);
        if (k < 2)
            CHECK(rc == 0 && !old_intact(path), "%s: renders (%d): %s", limits[k], rc, out);
        else
            CHECK(rc == 1 && strstr(out, "stack limit (ulimit -s) is 96 KiB") && old_intact(path),
                  "%s: exit 1 naming the limit, the older image whole (%d): %s", limits[k], rc,
                  out);
    }
}

/* A full disk: a 64 KiB tmpfs (where this machine lets the tests mount one), holding an
 * old file. Every image format fails with ENOSPC, exit 1, the old file whole. */
static void test_faults_full_disk(void)
{
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("full");
    char cmd[4096], out[4096], args[2048], path[1024];
    snprintf(cmd, sizeof cmd, "mount -t tmpfs -o size=64k vbcl-test-full '%s'", dir);
    if (tu_run(cmd, out, sizeof out) != 0) {
        th_skip("cannot mount a small tmpfs here (needs root and CAP_SYS_ADMIN)");
        return;
    }
    for (size_t i = 0; i < 4; i++) { /* the old files, then the disk filled to the last byte */
        snprintf(path, sizeof path, "%s/out.%s", dir, outputs[i]);
        put_old(path);
    }
    snprintf(cmd, sizeof cmd, "cat /dev/zero > '%s/filler'", dir);
    tu_run(cmd, NULL, 0);
    for (size_t i = 0; i < 4; i++) { /* png, exr, tif, jpg */
        const char *ext = outputs[i];
        snprintf(path, sizeof path, "%s/out.%s", dir, ext);
        snprintf(args, sizeof args, "%s --width 160 --height 160", scene);
        snprintf(cmd, sizeof cmd, "%s %s -q -o %s", tu_vbcl, args, path);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 1 && strstr(out, path) && strstr(out, "No space left on device"),
              "%s on a full disk: exit 1 naming the file and the cause (%d): %s", ext, rc, out);
        CHECK(old_intact(path), "%s: the older file is intact", ext);
        CHECK(!tu_dir_has(dir, ".tmp"), "%s: no temporary left", ext);
    }
    /* PoCL's kernel cache on the full disk: the build fails, and vbcl says why in one line
     * (before: "kernel build failed", an empty build log and CL_BUILD_PROGRAM_FAILURE) */
    if (tu_device() && strstr(tu_device()->name, "Portable Computing Language")) {
        snprintf(path, sizeof path, "%s/../cache-full.pfm", dir);
        snprintf(cmd, sizeof cmd, "POCL_CACHE_DIR='%s' %s %s -q --width 16 --height 16 -o %s", dir,
                 tu_vbcl, scene, path);
        int rc = tu_run(cmd, out, sizeof out);
        char *nl = strchr(out, '\n');
        CHECK(rc == 1 && strstr(out, "PoCL cannot write its kernel cache") && strstr(out, dir) &&
                  strstr(out, "No space left on device") && nl && nl[1] == 0,
              "PoCL's cache on a full disk: exit 1, one line naming it and the cause (%d): %s", rc,
              out);
    }
    snprintf(cmd, sizeof cmd, "umount '%s'", dir);
    tu_run(cmd, NULL, 0);
}

/* The shim's path (build/libvbcl_fault.so beside the vbcl under test). */
static const char *shim_path(void)
{
    static char path[1024];
    const char *slash = strrchr(tu_vbcl, '/');
    snprintf(path, sizeof path, "%.*slibvbcl_fault.so", slash ? (int)(slash - tu_vbcl + 1) : 0,
             tu_vbcl);
    return path;
}

/* Whether the shim is there (a failed check when it is not). */
static int shim_ready(void)
{
    int ok = access(shim_path(), R_OK) == 0;
    CHECK(ok, "the fault shim %s is missing (make builds it with the tests)", shim_path());
    return ok;
}

/* Runs vbcl with args under the fault shim (fault on files whose path holds part), with
 * the three signals' default actions (a background job starts with SIGINT ignored);
 * returns the exit status (128 + N for signal N). ASan may not come first under it. */
static int run_faulty(const char *fault, const char *part, const char *args, char *out, size_t n)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd,
             "exec env --default-signal=INT,TERM,HUP LD_PRELOAD=%s VBCL_FAULT=%s "
             "VBCL_FAULT_PATH=%s "
             "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0\" %s %s",
             shim_path(), fault, part, tu_vbcl, args);
    return tu_run(cmd, out, n);
}

/* The sync before the rename fails (an I/O error, or a quota or full disk that shows only
 * there): exit 1 with the cause, for every output. */
static void test_faults_sync_fails(void)
{
    if (!shim_ready()) return;
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("sync");
    char args[2048], out[4096], path[1024];
    for (size_t i = 0; i < sizeof outputs / sizeof outputs[0]; i++) {
        const char *ext = outputs[i];
        output_args(scene, dir, ext, args, sizeof args);
        snprintf(path, sizeof path, "%s/out.%s", dir, ext);
        put_old(path);
        const char *fault = i % 2 ? "ENOSPC" : "EIO";
        int rc = run_faulty(fault, ".out.", args, out, sizeof out);
        const char *cause = i % 2 ? "No space left on device" : "Input/output error";
        CHECK(rc == 1 && strstr(out, path) && strstr(out, cause),
              "%s, %s at the sync: exit 1 naming the file and the cause (%d): %s", ext, fault, rc,
              out);
        CHECK(old_intact(path), "%s: the older file is intact", ext);
        CHECK(!tu_dir_has(dir, ".tmp"), "%s: no temporary left", ext);
    }
}

/* SIGTERM, SIGINT and SIGHUP during the write: vbcl dies of the signal, the temporary is
 * removed, the older file is whole. */
static void test_faults_signal_in_write(void)
{
    if (!shim_ready()) return;
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("signal");
    static const struct {
        const char *name;
        int sig;
        const char *ext;
    } cases[] = {{"TERM", SIGTERM, "png"}, {"INT", SIGINT, "exr"}, {"HUP", SIGHUP, "json"}};
    char args[2048], out[4096], path[1024];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        output_args(scene, dir, cases[i].ext, args, sizeof args);
        snprintf(path, sizeof path, "%s/out.%s", dir, cases[i].ext);
        put_old(path);
        int rc = run_faulty(cases[i].name, ".out.", args, out, sizeof out);
        CHECK(rc == 128 + cases[i].sig, "SIG%s in the write of %s: died of it (%d): %s",
              cases[i].name, cases[i].ext, rc, out);
        CHECK(old_intact(path), "SIG%s: the older file is intact", cases[i].name);
        CHECK(!tu_dir_has(dir, ".tmp"), "SIG%s: no temporary left", cases[i].name);
    }
}

/* A scene whose glass sphere holds a generated texture, cached under VBCL_CACHE_DIR. */
#define TEXTURE_SCENE                                                                              \
    "{\"image\": {\"width\": 32, \"height\": 32},\n"                                               \
    " \"camera\": {\"eye\": [0, 0, 4], \"look_at\": [0, 0, 0]},\n"                                 \
    " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 0.5, \"flux\": 500}],\n"                    \
    " \"materials\": {\"glass\": {\"k_local\": 0.1, \"k_global\": 0.9, \"eta\": 1.5},\n"           \
    "                \"red\": {\"diffuse\": [0.9, 0.1, 0.1]}},\n"                                  \
    " \"objects\": [{\"shape\": \"sphere\", \"material\": \"glass\", \"texture\":\n"               \
    "   {\"generate\": \"bomb --count 6 --size 12:24 --seed 3 --no-overlap --level 1\",\n"         \
    "    \"material\": \"red\"}}]}\n"

/* The one cached texture in cache/textures (its path in out), or -1. */
static int cached_texture(const char *cache, char *out, size_t n)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/textures", cache);
    DIR *d = opendir(dir);
    int found = -1;
    for (struct dirent *e; d && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len > 4 && !strcmp(e->d_name + len - 4, ".ply")) {
            snprintf(out, n, "%s/%s", dir, e->d_name);
            found = 0;
        }
    }
    if (d) closedir(d);
    return found;
}

/* A cached texture cut short or with a byte changed is named, generated again and sealed,
 * and the image is the one the whole entry gave (today's build failed on the cut one and
 * rendered the changed one as it was). */
static void test_faults_damaged_texture_cache(void)
{
    const char *scene = tu_write_file("fault_texture.json", TEXTURE_SCENE);
    const char *cache = fault_dir("texcache");
    char cmd[4096], out[4096], ply[1024];
    static const char *const damage[] = {"truncate -s 1000 '%s'",
                                         "printf '\\377' | dd of='%s' bs=1 seek=2000 "
                                         "conv=notrunc 2>/dev/null"};
    static const char *const why[] = {"bytes where", "its checksum differs"};
    snprintf(cmd, sizeof cmd, "VBCL_CACHE_DIR=%s %s %s -q -o %s/first.pfm", cache, tu_vbcl, scene,
             cache);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && !out[0], "the first render: %s", out);
    CHECK(cached_texture(cache, ply, sizeof ply) == 0, "the texture is cached in %s", cache);
    for (int i = 0; i < 2; i++) {
        snprintf(cmd, sizeof cmd, damage[i], ply);
        tu_run(cmd, NULL, 0);
        snprintf(cmd, sizeof cmd, "VBCL_CACHE_DIR=%s %s %s -q -o %s/again.pfm", cache, tu_vbcl,
                 scene, cache);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0 && strstr(out, "cached texture is damaged") && strstr(out, why[i]),
              "damage %d: named and generated again (%d): %s", i, rc, out);
        snprintf(cmd, sizeof cmd, "cmp %s/first.pfm %s/again.pfm", cache, cache);
        CHECK(tu_run(cmd, out, sizeof out) == 0, "damage %d: the same image: %s", i, out);
        snprintf(cmd, sizeof cmd, "VBCL_CACHE_DIR=%s %s %s -q -o %s/again.pfm", cache, tu_vbcl,
                 scene, cache);
        CHECK(tu_run(cmd, out, sizeof out) == 0 && !out[0],
              "damage %d: the entry made again is whole: %s", i, out);
    }
}

/* Messages that name the real cause: no OpenCL platform at all (an empty vendors
 * directory for the ICD loader), on stderr also for --list-devices; a descriptor limit
 * too small to load the driver (it said "no OpenCL platform"); a bad VBCL_DEVICE named as
 * itself, not as --device. */
static void test_faults_device_messages(void)
{
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *empty = fault_dir("vendors");
    char cmd[4096], out[4096];
    snprintf(cmd, sizeof cmd, "(OCL_ICD_VENDORS=%s %s --list-devices 2>/dev/null)", empty, tu_vbcl);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && !out[0], "--list-devices with no platform: exit 1, nothing on stdout (%d): %s",
          rc, out);
    snprintf(cmd, sizeof cmd, "OCL_ICD_VENDORS=%s %s --list-devices", empty, tu_vbcl);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "no OpenCL platform") && strstr(out, "/etc/OpenCL/vendors"),
          "--list-devices with no platform says so on stderr (%d): %s", rc, out);
    snprintf(cmd, sizeof cmd, "OCL_ICD_VENDORS=%s %s %s -q -o %s/none.pfm", empty, tu_vbcl, scene,
             empty);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "no OpenCL platform"),
          "a render with no platform: exit 1 naming the cause (%d): %s", rc, out);
    /* a descriptor limit so small that the driver cannot be loaded: said as such */
    snprintf(cmd, sizeof cmd, "bash -c 'ulimit -n 4; exec %s %s -q -o %s/none.pfm'", tu_vbcl, scene,
             empty);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "descriptor limit, ulimit -n, is 4"),
          "ulimit -n 4: the descriptor limit named (%d): %s", rc, out);
    snprintf(cmd, sizeof cmd, "VBCL_DEVICE=nosuchdevice %s %s -q -o %s/none.pfm", tu_vbcl, scene,
             empty);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "VBCL_DEVICE=nosuchdevice: no device name contains") &&
              !strstr(out, "--device"),
          "a bad VBCL_DEVICE is named as itself (%d): %s", rc, out);
    snprintf(cmd, sizeof cmd, "VBCL_DEVICE=nosuchdevice %s %s -q --device 0 -o %s/zero.pfm",
             tu_vbcl, scene, empty);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "--device overrides VBCL_DEVICE (%d): %s", rc, out);
}

/* The image helper stopped (SIGSTOP) while vbcl renders: vbcl waits
 * VBCL_IMAGE_HELPER_TIMEOUT seconds for it, says so, kills it and encodes the image itself
 * (today's build waited forever); one killed during the write leaves the image to vbcl. A
 * descriptor limit below the helper's socket (ulimit -n 40) starts no helper, and says nothing
 * about it (today's build printed the helper's "not an option"). */
static void test_faults_image_helper(void)
{
    const char *scene = tu_write_file("fault_scene.json", FAULT_SCENE);
    const char *dir = fault_dir("helper");
    char cmd[4096], out[4096], img[1024];
    snprintf(img, sizeof img, "%s/stopped.png", dir);
    snprintf(cmd, sizeof cmd,
             "VBCL_IMAGE_HELPER_TIMEOUT=2 %s %s -q --width 128 --height 128 -o %s & p=$!; "
             "h=; for i in $(seq 200); do h=$(pgrep -P $p); [ -n \"$h\" ] && break; sleep 0.01; "
             "done; kill -STOP $h; wait $p; rc=$?; sleep 0.2; "
             "if kill -0 $h 2>/dev/null; then echo \"helper $h still there\"; kill -9 $h; fi; "
             "exit $rc",
             tu_vbcl, scene, img);
    char timed[4200];
    snprintf(timed, sizeof timed, "timeout 60 bash -c '%s'", cmd);
    int rc = tu_run(timed, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "did not answer in 2 s") && !strstr(out, "still there"),
          "a stopped helper: ended after 2 s, the image encoded by vbcl (%d): %s", rc, out);
    int w = 0, h = 0;
    float *pix = NULL;
    char err[512];
    CHECK(image_read(img, &w, &h, &pix, err, sizeof err) == 0 && w == 128 && h == 128,
          "the image is whole: %s", err);
    free(pix);
    /* Killed (SIGKILL) while vbcl waits for its answer: the temporary is there, vbcl finds
     * the helper gone, empties the temporary and encodes the image itself; no temporary
     * stays behind. */
    snprintf(img, sizeof img, "%s/killed.png", dir);
    snprintf(cmd, sizeof cmd,
             "VBCL_IMAGE_HELPER_TIMEOUT=60 %s %s -q --width 128 --height 128 -o %s & p=$!; "
             "h=; for i in $(seq 200); do h=$(pgrep -P $p); [ -n \"$h\" ] && break; sleep 0.01; "
             "done; kill -STOP $h; t=; for i in $(seq 3000); do "
             "t=$(ls -a %s | grep killed.png.tmp); [ -n \"$t\" ] && break; sleep 0.01; done; "
             "[ -n \"$t\" ] || echo \"no temporary seen\"; kill -9 $h; wait $p; rc=$?; "
             "ls -a %s | grep tmp; exit $rc",
             tu_vbcl, scene, img, dir, dir);
    snprintf(timed, sizeof timed, "timeout 60 bash -c '%s'", cmd);
    rc = tu_run(timed, out, sizeof out);
    CHECK(rc == 0 && !strstr(out, "tmp") && !strstr(out, "no temporary"),
          "a helper killed during the write: the image encoded by vbcl, no temporary (%d): %s", rc,
          out);
    CHECK(image_read(img, &w, &h, &pix, err, sizeof err) == 0 && w == 128 && h == 128,
          "the image is whole: %s", err);
    free(pix);
    snprintf(img, sizeof img, "%s/nofile.png", dir);
    snprintf(cmd, sizeof cmd, "bash -c 'ulimit -n 40; exec %s %s -q -o %s'", tu_vbcl, scene, img);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0 && !out[0], "ulimit -n 40: rendered, nothing said (%d): %s", rc, out);
    CHECK(image_read(img, &w, &h, &pix, err, sizeof err) == 0, "ulimit -n 40: the image: %s", err);
    free(pix);
}

/* A ray tree without bound: max_depth 64 with min_weight 0 between two glass slabs (2^64
 * rays a sample; the build before the cap did not finish 64 x 64 in 120 s). Each sample's
 * tree stops at VBCL_TREE_MAX_RAYS: the render ends, counts the branches left
 * (ray_tree.tree_cut) and warns. */
static void test_faults_unbounded_tree(void)
{
    const char *scene = tu_write_file(
        "fault_slabs.json",
        "{\"image\": {\"width\": 32, \"height\": 32},\n"
        " \"camera\": {\"eye\": [0, 0, 6], \"look_at\": [0, 0, 0]},\n"
        " \"render\": {\"max_depth\": 64, \"min_weight\": 0},\n"
        " \"materials\": {\"glass\": {\"k_local\": 0, \"k_global\": 1, \"eta\": 1.5}},\n"
        " \"objects\": [{\"shape\": \"box\", \"size\": [3, 3, 0.5], \"material\": \"glass\",\n"
        "               \"transform\": {\"translate\": [0, 0, 1]}},\n"
        "              {\"shape\": \"box\", \"size\": [3, 3, 0.5], \"material\": \"glass\",\n"
        "               \"transform\": {\"translate\": [0, 0, -1]}}]}\n");
    const char *dir = fault_dir("tree");
    char cmd[4096], out[4096], json[1024];
    snprintf(json, sizeof json, "%s/slabs.json", dir);
    snprintf(cmd, sizeof cmd, "timeout 120 %s %s -o %s/slabs.pfm --stats-json %s", tu_vbcl, scene,
             dir, json);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0 && strstr(out, "ray-tree branches were not traced"),
          "depth 64 unpruned between two slabs: finishes and warns (%d): %s", rc, out);
    static char text[1 << 16];
    tu_read_file(json, text, sizeof text);
    const char *cut = strstr(text, "\"tree_cut\":");
    CHECK(cut && atof(cut + strlen("\"tree_cut\":")) > 0, "ray_tree.tree_cut counted: %.80s",
          cut ? cut : text);
}

void suite_faults(void)
{
    RUN_TEST(test_faults_file_size_limit);
    RUN_TEST(test_faults_memory_limit);
    RUN_TEST(test_faults_small_stack);
    RUN_TEST(test_faults_full_disk);
    RUN_TEST(test_faults_sync_fails);
    RUN_TEST(test_faults_signal_in_write);
    RUN_TEST(test_faults_damaged_texture_cache);
    RUN_TEST(test_faults_device_messages);
    RUN_TEST(test_faults_image_helper);
    RUN_TEST(test_faults_unbounded_tree);
}
