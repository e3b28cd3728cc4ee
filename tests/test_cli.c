/* test_cli.c — the vbcl binary as a user meets it: help, devices, options, and bad input
 * of every class giving exit 2, a one-line message, and no output file touched. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>
#include <utime.h>

#include <cJSON.h>

#include "harness.h"
#include "image_io.h"
#include "testutil.h"
#include "types.h"

#define GOOD_SCENE                                                                                 \
    "{\"image\": {\"width\": 24, \"height\": 16},\n"                                               \
    " \"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0]},\n"                                 \
    " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 0.5, \"flux\": 500}],\n"                    \
    " \"materials\": {\"m\": {}},\n"                                                               \
    " \"objects\": [{\"shape\": \"sphere\", \"material\": \"m\"}]}\n"

/* A scene whose one object is the mesh file f (relative to the scene). */
#define MESH_SCENE(f)                                                                              \
    "{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"           \
    " \"objects\": [{\"shape\": \"mesh\", \"file\": \"" f "\", \"material\": \"m\"}]}"

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static int vbcl(const char *args, char *out, size_t n)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "timeout 300 %s %s", tu_vbcl, args); /* a hang fails (124) */
    return tu_run(cmd, out, n);
}

/* The file at path parsed as JSON, or NULL. */
static cJSON *read_json(const char *path)
{
    static char text[1 << 16];
    return cJSON_Parse(tu_read_file(path, text, sizeof text)); /* "" (no file): NULL */
}

/* The number at a path of object keys (NULL-terminated), or NAN where one is missing. */
static double json_num(const cJSON *o, ...)
{
    va_list ap;
    va_start(ap, o);
    for (const char *k = va_arg(ap, const char *); k && o; k = va_arg(ap, const char *))
        o = cJSON_GetObjectItemCaseSensitive(o, k);
    va_end(ap);
    return cJSON_IsNumber(o) ? o->valuedouble : NAN;
}

static void test_cli_help_and_usage(void)
{
    char out[8192];
    CHECK(vbcl("--help", out, sizeof out) == 0, "--help exits 0");
    CHECK(strstr(out, "usage: vbcl SCENE.json") && strstr(out, "--grid") &&
              strstr(out, "--list-devices") && strstr(out, "--stats") &&
              strstr(out, "--stats-json FILE"),
          "--help lists the options: %s", out);
    CHECK(vbcl("", out, sizeof out) == 2, "no scene: exit 2");
    CHECK(vbcl("--frobnicate x.json", out, sizeof out) == 2 && strstr(out, "--frobnicate"),
          "unknown option named: %s", out);
    CHECK(vbcl("scene.json --width", out, sizeof out) == 2 && strstr(out, "needs a value"),
          "missing value: %s", out);
    CHECK(vbcl("scene.json --width 0", out, sizeof out) == 2, "width 0 rejected");
}

/* The pid of the first LD_DEBUG line of out whose text holds `what`, or -1. vbcl's own is
 * the first to load libOpenCL (`timeout`, which runs it, loads none). */
static long ld_debug_pid(const char *out, const char *what)
{
    for (const char *l = out; *l;) {
        const char *end = l + strcspn(l, "\n");
        char line[1024];
        snprintf(line, sizeof line, "%.*s", (int)(end - l < 1023 ? end - l : 1023), l);
        long pid;
        char colon;
        if (sscanf(line, " %ld%c", &pid, &colon) == 2 && colon == ':' && strstr(line, what))
            return pid;
        l = *end ? end + 1 : end;
    }
    return -1;
}

/* vbcl loads OpenImageIO only to read or write an image, from the plugin embedded in it
 * (host/util/image_plugin.c): the binary does not link it, --help does not load it, and a
 * render has its PNG encoded by the helper process that loads it (another pid in the
 * dynamic loader's log), or by itself with VBCL_IMAGE_HELPER=0, the same bytes; the
 * helper is no option of the command line. */
static void test_cli_image_plugin(void)
{
    static char out[1 << 18];
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "ldd %s", tu_vbcl);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "libOpenCL") &&
              !strstr(out, "libOpenImageIO"),
          "vbcl does not link OpenImageIO: %s", out);
    snprintf(cmd, sizeof cmd, "LD_DEBUG=files %s --help", tu_vbcl);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "usage: vbcl") &&
              !strstr(out, "libOpenImageIO"),
          "--help loads no OpenImageIO");
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = tu_write_file("plugin.json", GOOD_SCENE);
    char img[512];
    snprintf(img, sizeof img, "%s/plugin.png", tu_tmpdir());
    snprintf(cmd, sizeof cmd, "LD_DEBUG=files timeout 300 %s %s -q -o %s --width 8 --height 8",
             tu_vbcl, scene, img);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "libOpenImageIO") && file_exists(img),
          "a render loads OpenImageIO and writes %s", img);
    long main_pid = ld_debug_pid(out, "libOpenCL"), oiio_pid = ld_debug_pid(out, "libOpenImageIO");
    CHECK(main_pid > 0 && oiio_pid > 0 && oiio_pid != main_pid,
          "a helper process loads OpenImageIO (pids %ld, %ld)", main_pid, oiio_pid);
    char here[512];
    snprintf(here, sizeof here, "%s/plugin_here.png", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "VBCL_IMAGE_HELPER=0 LD_DEBUG=files timeout 300 %s %s -q -o %s --width 8 --height 8",
             tu_vbcl, scene, here);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && file_exists(here), "VBCL_IMAGE_HELPER=0 writes %s",
          here);
    main_pid = ld_debug_pid(out, "libOpenCL");
    oiio_pid = ld_debug_pid(out, "libOpenImageIO");
    CHECK(main_pid > 0 && oiio_pid == main_pid,
          "VBCL_IMAGE_HELPER=0: vbcl loads OpenImageIO itself (pids %ld, %ld)", main_pid, oiio_pid);
    snprintf(cmd, sizeof cmd, "cmp %s %s", img, here);
    CHECK(tu_run(cmd, out, sizeof out) == 0,
          "the helper's PNG and vbcl's own are the same bytes: %s", out);
    snprintf(cmd, sizeof cmd, "%s --image-helper", tu_vbcl);
    CHECK(tu_run(cmd, out, sizeof out) == 2 && strstr(out, "not an option"),
          "--image-helper on the command line: exit 2, %s", out);
    /* a .pfm vbcl writes itself: a machine without OpenImageIO (a GPU node) still renders */
    snprintf(img, sizeof img, "%s/plugin.pfm", tu_tmpdir());
    snprintf(cmd, sizeof cmd, "LD_DEBUG=files timeout 300 %s %s -q -o %s --width 8 --height 8",
             tu_vbcl, scene, img);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && !strstr(out, "libOpenImageIO") && file_exists(img),
          "a render to .pfm loads no OpenImageIO and writes %s", img);
}

/* The kernel cache keeps within VBCL_CACHE_MAX_MB: a cold build that stores its binary
 * removes the least recently used binaries beyond it (never the new one, nor files that
 * are not binaries); a warm run marks its binary used; a bad value is named and the
 * default kept. */
static void test_cli_cache_pruned(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    char dir[512], path[1024], cmd[4096], out[8192];
    snprintf(dir, sizeof dir, "%s/prune-cache", tu_tmpdir());
    mkdir(dir, 0755);
    const char *names = "abcde"; /* a the oldest */
    for (int i = 0; i < 5; i++) {
        snprintf(path, sizeof path, "%s/%c.bin", dir, names[i]);
        FILE *f = fopen(path, "wb");
        for (int k = 0; f && k < 1 << 20; k++) fputc(0, f);
        if (f) fclose(f);
        struct utimbuf t = {946684800 + 86400 * i, 946684800 + 86400 * i}; /* 2000-01-0i */
        utime(path, &t);
    }
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    FILE *f = fopen(path, "w");
    if (f) fclose(f);
    const char *scene = tu_write_file("prune.json", GOOD_SCENE);
    snprintf(cmd, sizeof cmd,
             "VBCL_CACHE_BINARIES=1 VBCL_CACHE_DIR=%s VBCL_CACHE_MAX_MB=3 timeout 300 %s %s -q "
             "--stats -o %s/p.png "
             "--width 8 --height 8",
             dir, tu_vbcl, scene, tu_tmpdir());
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "compiled from source"),
          "a cold build: %s", out);
    uint64_t total = 0, fresh = 0;
    int kept[5] = {0}, fresh_n = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len < 4 || strcmp(e->d_name + len - 4, ".bin")) continue;
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (stat(path, &st)) continue;
        total += (uint64_t)st.st_size;
        if (len == 5 && strchr(names, e->d_name[0])) {
            kept[strchr(names, e->d_name[0]) - names] = 1;
        } else {
            if ((uint64_t)st.st_size > fresh) fresh = (uint64_t)st.st_size;
            fresh_n++;
        }
    }
    if (d) closedir(d);
    /* the film program's binary, stored first, may go for the tracing program's */
    CHECK(fresh_n >= 1 && fresh_n <= 2 && fresh > 0, "the new binaries are stored (%d)", fresh_n);
    CHECK(total <= (fresh > (3u << 20) ? fresh : (3u << 20)),
          "the binaries keep within 3 MB or the new one: %llu bytes", (unsigned long long)total);
    for (int i = 1; i < 5; i++)
        CHECK(!kept[i - 1] || kept[i], "the oldest go first: %c kept, %c not", names[i - 1],
              names[i]);
    CHECK(!kept[0], "the oldest dummy is gone");
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    CHECK(file_exists(path), "a file that is not a binary stays");
    snprintf(cmd, sizeof cmd,
             "VBCL_CACHE_BINARIES=1 VBCL_CACHE_DIR=%s VBCL_CACHE_MAX_MB=x timeout 300 %s %s -q "
             "--stats -o %s/p.png "
             "--width 8 --height 8",
             dir, tu_vbcl, scene, tu_tmpdir());
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "loaded from vbcl's binary cache") &&
              strstr(out, "VBCL_CACHE_MAX_MB=\"x\" is not a positive whole number"),
          "a warm run names the bad limit: %s", out);
}

/* Counts the files named *.bin in dir. */
static int bin_files(const char *dir)
{
    int n = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        n += len > 4 && !strcmp(e->d_name + len - 4, ".bin");
    }
    if (d) closedir(d);
    return n;
}

/* On a driver that keeps its own kernel cache (PoCL), vbcl stores no binary by default; the
 * first build vbcl's cache has no record of says "source", the next "source_driver_cache";
 * VBCL_CACHE_BINARIES=1 stores the two programs' binaries all the same, and a value other
 * than 0 or 1 is named. Elsewhere the default stores the binaries. */
static void test_cli_cache_binaries(void)
{
    VbDevice *dev = tu_device();
    if (!dev) {
        th_skip("no OpenCL device");
        return;
    }
    int pocl = strstr(dev->name, "Portable Computing Language") != NULL;
    char dir[512], cmd[4096], out[8192], json[600];
    const char *scene = tu_write_file("binaries.json", GOOD_SCENE);
    snprintf(json, sizeof json, "%s/binaries-stats.json", tu_tmpdir());
    const char *envs[3] = {"", "VBCL_CACHE_BINARIES=1", "VBCL_CACHE_BINARIES=yes"};
    for (int k = 0; k < 3; k++) {
        snprintf(dir, sizeof dir, "%s/binaries-cache-%d", tu_tmpdir(), k);
        mkdir(dir, 0755);
        for (int run = 0; run < 2; run++) {
            snprintf(cmd, sizeof cmd,
                     "%s VBCL_CACHE_DIR=%s timeout 300 %s %s -q -o %s/b.png --width 8 --height 8 "
                     "--stats-json %s",
                     envs[k], dir, tu_vbcl, scene, tu_tmpdir(), json);
            int rc = tu_run(cmd, out, sizeof out);
            cJSON *doc = read_json(json);
            const cJSON *prog = cJSON_GetObjectItemCaseSensitive(doc, "program");
            const char *got = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(prog, "from"));
            int stored = bin_files(dir), want = k == 1 || !pocl ? 2 : 0;
            const char *from = run == 0 ? "source" : want ? "binary" : "source_driver_cache";
            CHECK(rc == 0 && stored == want && got && !strcmp(got, from),
                  "%s, run %d: %d binaries stored, want %d; from %s, want %s: rc %d, %s",
                  envs[k][0] ? envs[k] : "default", run, stored, want, got ? got : "(none)", from,
                  rc, out);
            cJSON_Delete(doc);
        }
    }
    CHECK(strstr(out, "VBCL_CACHE_BINARIES=\"yes\" is not 0 or 1"), "a bad value is named: %s",
          out);
}

/* The largest *.bin in dir into path (the tracing program's binary); its size, or 0. */
static long largest_bin(const char *dir, char *path, size_t n)
{
    long best = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len <= 4 || strcmp(e->d_name + len - 4, ".bin")) continue;
        char p[1024];
        struct stat st;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (stat(p, &st) == 0 && st.st_size > best) {
            best = (long)st.st_size;
            snprintf(path, n, "%s", p);
        }
    }
    if (d) closedir(d);
    return best;
}

/* A cached binary cut short, or of the right length with bytes flipped inside, is found
 * out before the driver sees it: vbcl names it, removes it, builds from source, renders
 * the same image and stores a good binary again. */
static void test_cli_damaged_binary(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    char dir[512], cmd[4096], out[8192], bin[1024] = "", ref[600], img[600];
    snprintf(dir, sizeof dir, "%s/damaged-cache", tu_tmpdir());
    mkdir(dir, 0755);
    snprintf(ref, sizeof ref, "%s/damaged-ref.pfm", tu_tmpdir());
    snprintf(img, sizeof img, "%s/damaged.pfm", tu_tmpdir());
    const char *scene = tu_write_file("binary-scene.json", GOOD_SCENE);
    const char *base = "VBCL_CACHE_BINARIES=1 VBCL_CACHE_DIR=%s timeout 300 %s %s -q --stats -o %s "
                       "--width 16 --height 16";
    snprintf(cmd, sizeof cmd, base, dir, tu_vbcl, scene, ref);
    CHECK(tu_run(cmd, out, sizeof out) == 0, "the first render: %s", out);
    long size = largest_bin(dir, bin, sizeof bin);
    CHECK(size > 64, "a binary is stored: %ld bytes", size);
    if (size <= 64) return;
    for (int kind = 0; kind < 2; kind++) {
        if (kind == 0) {
            CHECK(truncate(bin, size / 2) == 0, "truncate %s", bin);
        } else {
            FILE *f = fopen(bin, "r+b");
            CHECK(f != NULL, "open %s", bin);
            if (!f) return;
            unsigned char b[16];
            fseek(f, size / 2, SEEK_SET);
            size_t got = fread(b, 1, sizeof b, f);
            for (size_t i = 0; i < got; i++) b[i] ^= 0x5a;
            fseek(f, size / 2, SEEK_SET);
            fwrite(b, 1, got, f);
            fclose(f);
        }
        snprintf(cmd, sizeof cmd, base, dir, tu_vbcl, scene, img);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0 && strstr(out, "a damaged cached kernel binary") &&
                  strstr(out, "compiled from source"),
              "%s: found out and rebuilt: rc %d, %s", kind ? "flipped bytes" : "truncated", rc,
              out);
        snprintf(cmd, sizeof cmd, "cmp -s %s %s", ref, img);
        CHECK(system(cmd) == 0, "%s: the same image as before", kind ? "flipped" : "truncated");
        struct stat st;
        CHECK(stat(bin, &st) == 0 && st.st_size == size, "%s: the binary is stored again (%ld)",
              kind ? "flipped" : "truncated", (long)st.st_size);
    }
    snprintf(cmd, sizeof cmd, base, dir, tu_vbcl, scene, img);
    CHECK(tu_run(cmd, out, sizeof out) == 0 && strstr(out, "loaded from vbcl's binary cache") &&
              !strstr(out, "a damaged cached kernel binary"),
          "the stored binary is good again: %s", out);
}

/* On a terminal, a render that compiles a program vbcl's cache has no record of says so
 * before it compiles; the next render of the same program does not, and neither does a
 * render whose stderr is not a terminal. --stats-json reports the build apart: the
 * kernels' first launches are in program.build_ms, and the render's wall time does not
 * overlap it. */
static void test_cli_compile_notice(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    if (system("command -v script > /dev/null 2>&1") != 0) {
        th_skip("no script(1) for a pseudo-terminal");
        return;
    }
    char dir[512], cmd[4096], out[8192], json[600];
    snprintf(dir, sizeof dir, "%s/notice-cache", tu_tmpdir());
    snprintf(json, sizeof json, "%s/notice-stats.json", tu_tmpdir());
    const char *scene = tu_write_file("notice.json", GOOD_SCENE);
    const char *notice = "compiling the opaque kernels";
    snprintf(cmd, sizeof cmd,
             "VBCL_CACHE_DIR=%s timeout 300 %s %s -o %s/notice-pipe.png --width 8 --height 8", dir,
             tu_vbcl, scene, tu_tmpdir());
    CHECK(tu_run(cmd, out, sizeof out) == 0 && !strstr(out, notice),
          "no notice without a terminal: %s", out);
    snprintf(dir, sizeof dir, "%s/notice-cache-tty", tu_tmpdir());
    for (int run = 0; run < 2; run++) {
        snprintf(cmd, sizeof cmd,
                 "script -qec 'VBCL_CACHE_DIR=%s timeout 300 %s %s -o %s/notice.png --width 8 "
                 "--height 8 --stats-json %s' /dev/null",
                 dir, tu_vbcl, scene, tu_tmpdir(), json);
        int rc = tu_run(cmd, out, sizeof out);
        CHECK(rc == 0 && (run == 0) == (strstr(out, notice) != NULL),
              "run %d on a terminal: the notice %s: rc %d, %s", run, run ? "not again" : "first",
              rc, out);
    }
    cJSON *doc = read_json(json);
    const cJSON *prog = cJSON_GetObjectItemCaseSensitive(doc, "program");
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(doc, "time_ms");
    double build = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(prog, "build_ms"));
    double first = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(prog, "first_launch_ms"));
    double render = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(t, "render"));
    double total = cJSON_GetNumberValue(cJSON_GetObjectItemCaseSensitive(t, "total"));
    CHECK(first > 0.0 && build >= first && render >= 0.0 && build + render <= total + 1.0,
          "the build apart from the render: build %.1f (first launches %.1f), render %.1f, total "
          "%.1f ms",
          build, first, render, total);
    cJSON_Delete(doc);
}

static void test_cli_list_devices(void)
{
    char out[8192];
    int rc = vbcl("--list-devices", out, sizeof out);
    CHECK(rc == 0, "--list-devices exits 0 (%d): %s", rc, out);
    CHECK(strncmp(out, "0: ", 3) == 0, "devices listed with an index: %s", out);
}

static void test_cli_renders_and_overrides(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = tu_write_file("good.json", GOOD_SCENE);
    char out[8192], args[2048], img[512];
    snprintf(img, sizeof img, "%s/good.exr", tu_tmpdir());
    snprintf(args, sizeof args, "%s -o %s --width 20 --height 10 --grid 4:2,3,1 --stats", scene,
             img);
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 0, "render exits 0 (%d): %s", rc, out);
    CHECK(strstr(out, "(20x10)") != NULL, "command line overrides the size: %s", out);
    CHECK(strstr(out, "4x4x4") != NULL, "command line overrides the grid: %s", out);
    CHECK(strstr(out, "sub-grids") && strstr(out, "(given)"), "--grid TOP:SUB given: %s", out);
    CHECK(strstr(out, "rays        primary 200") != NULL, "--stats counts primary rays: %s", out);
    CHECK(file_exists(img), "image written");
    /* every output format, read back: 8-bit sRGB ones and linear float EXR agree, and the
     * PFM vbcl writes itself holds the EXR's very floats, rows bottom to top (OpenImageIO
     * reads it; the image is not square, so a flip or a transposition shows) */
    const char *exts[] = {"png", "jpg", "tif", "exr", "pfm"};
    float *pix[5] = {NULL, NULL, NULL, NULL, NULL};
    for (int i = 0; i < 5; i++) {
        char path[512], err[512];
        int w = 0, h = 0;
        snprintf(path, sizeof path, "%s/fmt.%s", tu_tmpdir(), exts[i]);
        snprintf(args, sizeof args, "%s -q -o %s --width 12 --height 8", scene, path);
        CHECK(vbcl(args, out, sizeof out) == 0, "writes .%s: %s", exts[i], out);
        CHECK(image_read(path, &w, &h, &pix[i], err, sizeof err) == 0 && w == 12 && h == 8,
              ".%s reads back as 12x8: %s", exts[i], err);
    }
    if (pix[0] && pix[1] && pix[2] && pix[3]) {
        double worst_png = 0, worst_jpg = 0;
        for (int k = 0; k < 12 * 8 * 4; k++) {
            if (k % 4 == 3) continue;
            double lin = pix[3][k] <= 0 ? 0 : pix[3][k] >= 1 ? 1 : pix[3][k];
            double enc = lin <= 0.0031308 ? 12.92 * lin : 1.055 * pow(lin, 1 / 2.4) - 0.055;
            worst_png = fmax(worst_png, fmax(fabs(pix[0][k] - enc), fabs(pix[2][k] - enc)));
            worst_jpg = fmax(worst_jpg, fabs(pix[1][k] - enc));
        }
        CHECK(worst_png <= 0.5 / 255 + 1e-6, "PNG and TIFF are the EXR, sRGB-encoded (worst %g)",
              worst_png);
        CHECK(worst_jpg <= 0.15, "JPEG close to the EXR (worst %g)", worst_jpg);
    }
    if (pix[3] && pix[4])
        CHECK(memcmp(pix[3], pix[4], sizeof(float) * 12 * 8 * 4) == 0,
              "the PFM's floats are the EXR's");
    {
        char path[512], head[16] = "";
        snprintf(path, sizeof path, "%s/fmt.pfm", tu_tmpdir());
        FILE *f = fopen(path, "rb");
        long size = -1;
        if (f) {
            size_t k = fread(head, 1, 13, f);
            head[k] = '\0';
            fseek(f, 0, SEEK_END);
            size = ftell(f);
            fclose(f);
        }
        CHECK(strcmp(head, "PF\n12 8\n-1.0\n") == 0 && size == 13 + 12 * 8 * 12,
              "PFM header (little-endian RGB) and size %ld", size);
    }
    for (int i = 0; i < 5; i++) free(pix[i]);
    /* from another working directory: kernels are embedded, mesh paths are scene-relative */
    snprintf(args, sizeof args, "cd / && %s%s -q %s -o %s/good.png",
             tu_vbcl[0] == '/' ? "" : "\"$OLDPWD\"/", tu_vbcl, scene, tu_tmpdir());
    rc = tu_run(args, out, sizeof out);
    CHECK(rc == 0 && out[0] == 0, "runs from another directory, -q prints nothing (%d): %s", rc,
          out);
    CHECK(vbcl("--device 99 --list-devices", out, sizeof out) == 0, "listing ignores --device");
    snprintf(args, sizeof args, "%s -o %s/x.png --device 99", scene, tu_tmpdir());
    CHECK(vbcl(args, out, sizeof out) == 2 && strstr(out, "no such device"), "bad device index: %s",
          out);
    snprintf(args, sizeof args, "%s -o %s/x.png --device no-such-gpu", scene, tu_tmpdir());
    CHECK(vbcl(args, out, sizeof out) == 2 && strstr(out, "no-such-gpu"), "bad device name: %s",
          out);
}

/* A bad input must give exit 2, a one-line message containing `needle`, and leave the
 * existing output file exactly as it was. */
static void expect_bad(const char *scene_text, const char *extra_args, const char *needle)
{
    tu_expect_refused(tu_write_file("bad.json", scene_text), extra_args ? extra_args : "", needle);
}

/* An animation that moves its quad out of the view: the geometry of each frame is built
 * anew (compile.geometry_built 1) and the moved quad is seen where it is, not where the
 * last frame's geometry had it. */
static void frames_moving_quad(void)
{
    const char *scene = tu_write_file(
        "anim_move.json",
        "{\"image\": {\"width\": 8, \"height\": 8, \"background\": [0, 0, 0]},"
        " \"camera\": {\"eye\": [0, 0, 5], \"look_at\": [0, 0, 0]},"
        " \"render\": {\"ambient\": [1, 1, 1]},"
        " \"materials\": {\"m\": {\"ambient\": [0.5, 0.5, 0.5], \"diffuse\": [0, 0, 0]}},"
        " \"objects\": [{\"shape\": \"quad\", \"size\": [20, 20], \"material\": \"m\","
        "   \"transform\": {\"rotate\": [90, 0, 0], \"translate\": [0, 0, 0]}}],"
        " \"animation\": {\"frames\": 2, \"tracks\": [{\"target\":"
        " \"objects.0.transform.translate\", \"keys\": [[0, [0, 0, 0]], [1, [100, 0, 0]]]}]}}");
    char out[8192], args[2048], json[512], path[512], err[512];
    snprintf(json, sizeof json, "%s/anim_move.json.stats", tu_tmpdir());
    snprintf(args, sizeof args, "%s -o %s/move_#.exr --stats-json %s", scene, tu_tmpdir(), json);
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 0, "moving quad: exit %d: %s", rc, out);
    cJSON *doc = read_json(json);
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(doc, "frames");
    for (int k = 0; k < 2; k++)
        CHECK(json_num(cJSON_GetArrayItem(frames, k), "compile", "geometry_built", NULL) == 1,
              "moving quad: frame %d builds its geometry", k);
    cJSON_Delete(doc);
    for (int f = 0; f < 2; f++) {
        float *px = NULL;
        int w, h;
        snprintf(path, sizeof path, "%s/move_%d.exr", tu_tmpdir(), f);
        if (image_read(path, &w, &h, &px, err, sizeof err)) {
            CHECK(0, "%s", err);
            continue;
        }
        double want = f == 0 ? 0.5 : 0.0; /* the quad, then the background */
        CHECK(fabs(px[4 * (4 * w + 4)] - want) < 1e-5, "moving quad: frame %d centre %g, want %g",
              f, px[4 * (4 * w + 4)], want);
        free(px);
    }
}

/* --frames renders numbered frames of an animated scene: a run of # in -o becomes the frame
 * number; the frames differ as the animation says. */
static void test_cli_frames(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = tu_write_file(
        "anim_cli.json",
        "{\"image\": {\"width\": 8, \"height\": 8},"
        " \"camera\": {\"eye\": [0, 0, 5], \"look_at\": [0, 0, 0]},"
        " \"render\": {\"ambient\": [1, 1, 1]},"
        " \"materials\": {\"m\": {\"ambient\": [0, 0, 0], \"diffuse\": [0, 0, 0]}},"
        " \"objects\": [{\"shape\": \"quad\", \"size\": [20, 20], \"material\": \"m\","
        "   \"transform\": {\"rotate\": [90, 0, 0]}}],"
        " \"animation\": {\"frames\": 3, \"tracks\": [{\"target\": \"materials.m.ambient\","
        "   \"keys\": [[0, [0, 0, 0]], [2, [0.5, 0.5, 0.5]]]}]}}");
    char out[8192], args[2048], pattern[512], path[512];
    snprintf(pattern, sizeof pattern, "%s/frame_###.exr", tu_tmpdir());
    char json[512];
    snprintf(json, sizeof json, "%s/anim_stats.json", tu_tmpdir());
    snprintf(args, sizeof args, "%s -o %s --frames 1:2 --stats-json %s", scene, pattern, json);
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 0, "--frames 1:2 exits 0 (%d): %s", rc, out);
    /* --stats-json: one document, an object per frame rendered */
    cJSON *doc = read_json(json);
    const cJSON *frames = cJSON_GetObjectItemCaseSensitive(doc, "frames");
    CHECK(cJSON_GetArraySize(frames) == 2 && json_num(doc, "frames_in_scene", NULL) == 3,
          "--stats-json of frames 1:2 has two frames of 3");
    for (int k = 0; k < cJSON_GetArraySize(frames); k++) {
        const cJSON *fk = cJSON_GetArrayItem(frames, k);
        CHECK(json_num(fk, "frame", NULL) == 1 + k && json_num(fk, "rays", "primary", NULL) == 64,
              "frames[%d] is frame %d with 64 primary rays", k, 1 + k);
        /* only a material changes: the second frame keeps the first's geometry */
        CHECK(json_num(fk, "compile", "scenes", NULL) == 1 &&
                  json_num(fk, "compile", "geometry_built", NULL) == (k == 0),
              "frames[%d]: one compile, geometry %s", k, k == 0 ? "built" : "kept");
    }
    cJSON_Delete(doc);
    frames_moving_quad();
    for (int f = 0; f < 3; f++) {
        snprintf(path, sizeof path, "%s/frame_%03d.exr", tu_tmpdir(), f);
        CHECK(file_exists(path) == (f >= 1), "frame %d %s", f, f >= 1 ? "missing" : "written");
        if (f == 0) continue;
        float *px = NULL;
        int w, h;
        char err[512];
        if (image_read(path, &w, &h, &px, err, sizeof err)) {
            CHECK(0, "%s", err);
            continue;
        }
        double want = 0.25 * f; /* ambient light 1 times the animated ambient colour */
        CHECK(fabs(px[0] - want) < 1e-5, "frame %d: pixel %g, want %g", f, px[0], want);
        free(px);
    }
    /* without #: _NNNN before the extension */
    snprintf(args, sizeof args, "%s -o %s/anim.png --frames 2", scene, tu_tmpdir());
    rc = vbcl(args, out, sizeof out);
    snprintf(path, sizeof path, "%s/anim_0002.png", tu_tmpdir());
    CHECK(rc == 0 && file_exists(path), "--frames 2 writes anim_0002.png: %s", out);
    /* frames the scene does not have, and a scene without animation */
    snprintf(args, sizeof args, "%s -o %s/x.png --frames 1:3", scene, tu_tmpdir());
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "frames 0 to 2"), "--frames 1:3 of 3: %d %s", rc, out);
    const char *plain = tu_write_file("plain_cli.json", GOOD_SCENE);
    snprintf(args, sizeof args, "%s -o %s/x.png --frames 0", plain, tu_tmpdir());
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "not animated"), "--frames on a still scene: %d %s", rc, out);
    snprintf(args, sizeof args, "%s --frames 2:1", scene);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--frames"), "--frames 2:1: %d %s", rc, out);
}

/* render.shadow_jitter false puts every feeler at its stratum's centre: two seeds give the
 * same image; jittered feelers (the default) differ with the seed. */
static void test_cli_fixed_feelers(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    float *img[4] = {NULL};
    int w = 0, h = 0;
    for (int k = 0; k < 4; k++) {
        char text[2048], out[4096], args[2048], path[512], err[512];
        snprintf(text, sizeof text,
                 "{\"image\": {\"width\": 24, \"height\": 24},"
                 " \"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0]},"
                 " \"render\": {\"seed\": %d, \"shadow_samples\": 4, \"shadow_jitter\": %s},"
                 " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 1.5, \"flux\": 500}],"
                 " \"materials\": {\"m\": {}},"
                 " \"objects\": [{\"shape\": \"sphere\", \"material\": \"m\"},"
                 "   {\"shape\": \"quad\", \"size\": [8, 8], \"material\": \"m\","
                 "    \"transform\": {\"translate\": [0, -1, 0]}}]}",
                 1 + k % 2, k < 2 ? "false" : "true");
        const char *scene = tu_write_file("jitter.json", text);
        snprintf(path, sizeof path, "%s/jitter%d.exr", tu_tmpdir(), k);
        snprintf(args, sizeof args, "%s -q -o %s", scene, path);
        CHECK(vbcl(args, out, sizeof out) == 0, "render %d: %s", k, out);
        if (image_read(path, &w, &h, &img[k], err, sizeof err)) CHECK(0, "%s", err);
    }
    if (img[0] && img[1] && img[2] && img[3]) {
        double fixed = 0, jittered = 0;
        for (int i = 0; i < w * h * 4; i++) {
            fixed = fmax(fixed, fabs(img[0][i] - img[1][i]));
            jittered = fmax(jittered, fabs(img[2][i] - img[3][i]));
        }
        CHECK(fixed == 0.0, "fixed feelers differ with the seed by %g", fixed);
        CHECK(jittered > 1e-3, "jittered feelers do not depend on the seed (%g)", jittered);
    }
    for (int k = 0; k < 4; k++) free(img[k]);
}

/* Renders scene at 40 x 40 with 4 feelers and extra options into TMP/TAG.exr (the image in
 * *img); returns its --stats-json document (the caller deletes it). */
static cJSON *render_40(const char *scene, const char *tag, const char *opts, float **img, int *w,
                        int *h)
{
    char out[8192], args[2048], path[512], json[512], err[512];
    snprintf(path, sizeof path, "%s/%s.exr", tu_tmpdir(), tag);
    snprintf(json, sizeof json, "%s/%s.json", tu_tmpdir(), tag);
    snprintf(args, sizeof args,
             "%s -q --width 40 --height 40 --shadow-samples 4 -o %s --stats-json %s %s", scene,
             path, json, opts);
    CHECK(vbcl(args, out, sizeof out) == 0, "%s: %s", args, out);
    if (image_read(path, w, h, img, err, sizeof err)) CHECK(0, "%s", err);
    return read_json(json);
}

/* The shadow cone test (light.cl, light_cone_objects) leaves feelers untraced only where
 * tracing them finds nothing: on scenes with planar, convex, textured, transparent and
 * dispersive objects, the image is bit-identical to --no-cone-test's, which traces every
 * feeler, and the feelers it did not trace (clear, or blocked by the core of a solid texture
 * part, some of A.4's, or of an opaque convex object: spheres36's spheres of 5120 triangles,
 * convex by mesh_part_convex) are exactly the ones missing from the count. */
static void test_cli_cone_test(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    static const char *const scenes[] = {
        "scenes/quickstart.json",           "scenes/glass_bombed_sphere.json",
        "scenes/thesis/a4_two_prisms.json", "scenes/bench/spheres36.json",
        "scenes/thesis/a5_dispersion.json", "scenes/thesis/a2_marble.json"};
    double blocked_part = 0, blocked_object = 0;
    for (size_t n = 0; n < sizeof scenes / sizeof *scenes; n++) {
        float *img[2] = {NULL, NULL};
        double shadow[2] = {0, 0}, clear[2] = {0, 0}, blocked[2] = {0, 0};
        int w = 0, h = 0;
        for (int k = 0; k < 2; k++) {
            cJSON *doc = render_40(scenes[n], k ? "cone1" : "cone0",
                                   k ? "--aa 0 --no-cone-test" : "--aa 0", &img[k], &w, &h);
            shadow[k] = json_num(doc, "rays", "shadow", NULL);
            clear[k] = json_num(doc, "rays", "shadow_clear", NULL);
            blocked[k] = json_num(doc, "rays", "shadow_blocked", NULL);
            cJSON_Delete(doc);
        }
        if (img[0] && img[1]) {
            double diff = 0;
            for (int i = 0; i < w * h * 4; i++) diff = fmax(diff, fabs(img[0][i] - img[1][i]));
            CHECK(diff == 0.0, "%s: the cone test changes the image by up to %g", scenes[n], diff);
        }
        CHECK(clear[1] == 0 && clear[0] > 0,
              "%s: feelers left untraced with and without the "
              "cone test: %g, %g",
              scenes[n], clear[0], clear[1]);
        CHECK(shadow[0] + clear[0] + blocked[0] == shadow[1] && blocked[1] == 0,
              "%s: %g traced + %g clear + %g blocked != %g traced "
              "without the test (%g blocked)",
              scenes[n], shadow[0], clear[0], blocked[0], shadow[1], blocked[1]);
        if (strstr(scenes[n], "spheres36"))
            blocked_object += blocked[0];
        else
            blocked_part += blocked[0];
        free(img[0]);
        free(img[1]);
    }
    CHECK(blocked_part > 0, "no feeler passed through a solid texture part's core (A.4's spheres)");
    CHECK(blocked_object > 0, "no feeler passed through an opaque object's core (spheres36)");
}

/* Camera tiles (camera_trace_closest) find the grid's hits: with anti-aliasing, whose
 * refinement rays are camera rays too, the image is bit-identical to --no-camera-tiles's on
 * opaque, textured, transparent and dispersive scenes, and camera rays visit fewer cells. */
static void test_cli_camera_tiles(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    static const char *const scenes[] = {
        "scenes/quickstart.json", "scenes/glass_bombed_sphere.json",
        "scenes/thesis/a4_two_prisms.json", "scenes/thesis/a5_dispersion.json"};
    for (size_t n = 0; n < sizeof scenes / sizeof *scenes; n++) {
        float *img[2] = {NULL, NULL};
        double cells[2] = {0, 0}, spp = 0;
        int w = 0, h = 0;
        for (int k = 0; k < 2; k++) {
            cJSON *doc = render_40(scenes[n], k ? "ctile1" : "ctile0",
                                   k ? "--aa 0.1 --no-camera-tiles" : "--aa 0.1", &img[k], &w, &h);
            cells[k] = json_num(doc, "work", "cells_visited", NULL);
            spp = json_num(doc, "samples", "per_pixel_mean", NULL);
            cJSON_Delete(doc);
        }
        if (img[0] && img[1]) {
            double diff = 0;
            for (int i = 0; i < w * h * 4; i++) diff = fmax(diff, fabs(img[0][i] - img[1][i]));
            CHECK(diff == 0.0, "%s: camera tiles change the image by up to %g", scenes[n], diff);
        }
        CHECK(spp > 1.0, "%s: some pixels refined (%g samples per pixel)", scenes[n], spp);
        CHECK(cells[0] < cells[1], "%s: cells visited with tiles %g, without %g", scenes[n],
              cells[0], cells[1]);
        free(img[0]);
        free(img[1]);
    }
}

/* Renders scene at 48 x 48 with extra options; the image in *img, rays.shadow in *shadow
 * and the stats entry section.name in *value. */
static void render_counted(const char *scene, const char *tag, const char *opts, float **img,
                           int *w, int *h, double *shadow, const char *section, const char *name,
                           double *value)
{
    char out[8192], args[2048], path[512], json[512], err[512];
    snprintf(path, sizeof path, "%s/count_%s.exr", tu_tmpdir(), tag);
    snprintf(json, sizeof json, "%s/count_%s.json", tu_tmpdir(), tag);
    snprintf(args, sizeof args, "%s -q --width 48 --height 48 -o %s --stats-json %s %s", scene,
             path, json, opts);
    CHECK(vbcl(args, out, sizeof out) == 0, "%s: %s", args, out);
    if (image_read(path, w, h, img, err, sizeof err)) CHECK(0, "%s", err);
    cJSON *doc = read_json(json);
    *shadow = json_num(doc, "rays", "shadow", NULL);
    *value = json_num(doc, section, name, NULL);
    cJSON_Delete(doc);
}

/* render_counted with one sample per pixel, ray_tree.reflected in *reflected. */
static void render_feelers(const char *scene, const char *tag, const char *opts, float **img,
                           int *w, int *h, double *shadow, double *reflected)
{
    char all[1024];
    snprintf(all, sizeof all, "--aa 0 %s", opts);
    render_counted(scene, tag, all, img, w, h, shadow, "ray_tree", "reflected", reflected);
}

/* Sample shares (render.sample_shares, sample_share): with adaptive anti-aliasing and
 * feelers by weight, the ray-tree points of a quadtree sample fresh at level L count 2^-L
 * of their weight. On A.4 at --aa 0.05 the refinement samples trace fewer feelers each than
 * with --no-sample-shares (pass 0, the same in both, subtracted), and the image's mean stays
 * within 0.5%. Pass 0 alone (--aa 0), uniform supersampling (--ssaa 2) and a scene without
 * ray trees (the quickstart, --aa 0.05) are bit for bit --no-sample-shares's. */
static void test_cli_sample_shares(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    static const char *const a4 = "scenes/thesis/a4_two_prisms.json";
    static const struct {
        const char *scene, *opts;
    } runs[] = {{a4, "--aa 0"}, /* first: pass 0 alone, whose feelers run 1 subtracts */
                {a4, "--aa 0.05"},
                {a4, "--ssaa 2"},
                {"scenes/quickstart.json", "--aa 0.05"}};
    double shadow0 = 0;
    for (int k = 0; k < 4; k++) {
        float *img[2] = {NULL, NULL};
        double shadow[2], refine[2], diff = 0, mean[2] = {0, 0};
        int w = 0, h = 0;
        char tag[16], opts[256];
        for (int j = 0; j < 2; j++) {
            snprintf(tag, sizeof tag, "%d%d", k, j);
            snprintf(opts, sizeof opts, "%s%s", runs[k].opts, j ? " --no-sample-shares" : "");
            render_counted(runs[k].scene, tag, opts, &img[j], &w, &h, &shadow[j], "rays",
                           "refinement", &refine[j]);
        }
        if (k == 0) shadow0 = shadow[0];
        if (!img[0] || !img[1]) goto next;
        for (int i = 0; i < w * h * 4; i++) {
            diff = fmax(diff, fabs(img[0][i] - img[1][i]));
            if (i % 4 == 3) continue; /* alpha */
            mean[0] += img[0][i];
            mean[1] += img[1][i];
        }
        if (k != 1) {
            CHECK(diff == 0.0 && shadow[0] == shadow[1],
                  "%s %s: differs from --no-sample-shares by %g (%g against %g feelers)",
                  runs[k].scene, runs[k].opts, diff, shadow[0], shadow[1]);
            goto next;
        }
        double per[2] = {(shadow[0] - shadow0) / refine[0], (shadow[1] - shadow0) / refine[1]};
        CHECK(refine[0] > 500 && refine[1] > 500, "%g and %g refinement samples", refine[0],
              refine[1]);
        CHECK(per[0] < 0.9 * per[1], "%g feelers per refinement sample, %g without shares", per[0],
              per[1]);
        CHECK(fabs(mean[0] - mean[1]) <= 5e-3 * mean[1], "mean %g, %g without shares",
              mean[0] / (3.0 * w * h), mean[1] / (3.0 * w * h));
        printf("    A.4 %s: %.0f and %.0f refinement samples, %.2f and %.2f feelers each; mean "
               "%.6g, %.6g\n",
               runs[k].opts, refine[0], refine[1], per[0], per[1], mean[0] / (3.0 * w * h),
               mean[1] / (3.0 * w * h));
    next:
        free(img[0]);
        free(img[1]);
    }
}

/* Feelers by weight (render.shadow_by_weight, light_node_strata): a point deeper in a ray
 * tree that weighs w <= 1/4 in its sample gets about w x 16 of the 16 feelers. On scenes
 * without ray trees the image is bit-identical to --all-feelers's; with them fewer feelers
 * are traced, the image's mean stays within 0.2% of --all-feelers's (a feeler count of 4 or
 * 1 where the estimate still divided by 16 would darken those points 4 to 16 times, about
 * 1% of A.4's mean), and the difference to --all-feelers with the same seed is smaller than
 * the noise between two seeds of --all-feelers (the primary points' feelers are the same).
 * "shadow_by_weight": false in the scene is --all-feelers, bit for bit. */
static void test_cli_feelers_by_weight(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    static const char *const scenes[] = {
        "scenes/quickstart.json", "scenes/glass_bombed_sphere.json",
        "scenes/thesis/a4_two_prisms.json", "scenes/thesis/a2_marble.json"};
    int trees = 0;
    for (size_t n = 0; n < sizeof scenes / sizeof *scenes; n++) {
        float *img[3] = {NULL, NULL, NULL};
        double shadow[3], reflected[3];
        int w = 0, h = 0;
        render_feelers(scenes[n], "w", "", &img[0], &w, &h, &shadow[0], &reflected[0]);
        render_feelers(scenes[n], "a", "--all-feelers", &img[1], &w, &h, &shadow[1], &reflected[1]);
        render_feelers(scenes[n], "b", "--all-feelers --seed 2", &img[2], &w, &h, &shadow[2],
                       &reflected[2]);
        if (!img[0] || !img[1] || !img[2]) goto next;
        double diff = 0, mean[2] = {0, 0}, rms_wa = 0, rms_ab = 0;
        size_t np = (size_t)w * (size_t)h;
        for (size_t i = 0; i < np; i++)
            for (int c = 0; c < 3; c++) {
                double a = img[0][4 * i + c], b = img[1][4 * i + c], e = img[2][4 * i + c];
                diff = fmax(diff, fabs(a - b));
                mean[0] += a;
                mean[1] += b;
                rms_wa += (a - b) * (a - b);
                rms_ab += (b - e) * (b - e);
            }
        if (reflected[1] == 0) {
            CHECK(diff == 0.0 && shadow[0] == shadow[1],
                  "%s: no ray trees, yet weighting changes the image by %g (%g, %g feelers)",
                  scenes[n], diff, shadow[0], shadow[1]);
            goto next;
        }
        trees++;
        CHECK(shadow[0] < 0.95 * shadow[1], "%s: %g feelers by weight, %g all of them", scenes[n],
              shadow[0], shadow[1]);
        CHECK(fabs(mean[0] - mean[1]) <= 2e-3 * mean[1], "%s: mean %g by weight, %g with all",
              scenes[n], mean[0] / (3.0 * np), mean[1] / (3.0 * np));
        CHECK(rms_wa < rms_ab, "%s: RMS %g from --all-feelers, two seeds of it differ by %g",
              scenes[n], sqrt(rms_wa / (3.0 * np)), sqrt(rms_ab / (3.0 * np)));
        printf("    %s: feelers %.0f by weight, %.0f all; mean %.6g, %.6g; RMS %.3g (seeds %.3g)\n",
               scenes[n], shadow[0], shadow[1], mean[0] / (3.0 * np), mean[1] / (3.0 * np),
               sqrt(rms_wa / (3.0 * np)), sqrt(rms_ab / (3.0 * np)));
    next:
        for (int k = 0; k < 3; k++) free(img[k]);
    }
    CHECK(trees >= 3, "only %d of the scenes have ray trees", trees);
    /* the scene's switch is the option */
    char text[1024], out[4096], args[2048], path[2][512], err[512];
    float *img[2] = {NULL, NULL};
    int w = 0, h = 0;
    for (int k = 0; k < 2; k++) {
        snprintf(text, sizeof text,
                 "{\"image\": {\"width\": 24, \"height\": 24},"
                 " \"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0]},"
                 " \"render\": {\"shadow_by_weight\": %s},"
                 " \"lights\": [{\"centre\": [2, 4, 3], \"radius\": 1.5, \"flux\": 500}],"
                 " \"materials\": {\"g\": {\"diffuse\": [0, 0, 0], \"k_global\": 0.9,"
                 "   \"k_local\": 0.1, \"eta\": 1.5}, \"m\": {}},"
                 " \"objects\": [{\"shape\": \"sphere\", \"material\": \"g\"},"
                 "   {\"shape\": \"quad\", \"size\": [8, 8], \"material\": \"m\","
                 "    \"transform\": {\"translate\": [0, -1, 0]}}]}",
                 k ? "true" : "false");
        const char *scene = tu_write_file("byweight.json", text);
        snprintf(path[k], sizeof path[k], "%s/byweight%d.exr", tu_tmpdir(), k);
        snprintf(args, sizeof args, "%s -q -o %s%s", scene, path[k], k ? " --all-feelers" : "");
        CHECK(vbcl(args, out, sizeof out) == 0, "render %d: %s", k, out);
        if (image_read(path[k], &w, &h, &img[k], err, sizeof err)) CHECK(0, "%s", err);
    }
    if (img[0] && img[1]) {
        double diff = 0;
        for (int i = 0; i < w * h * 4; i++) diff = fmax(diff, fabs(img[0][i] - img[1][i]));
        CHECK(diff == 0.0, "shadow_by_weight false and --all-feelers differ by %g", diff);
    }
    free(img[0]);
    free(img[1]);
}

static void test_cli_bad_input_classes(void)
{
    expect_bad("{\"camera\": ", NULL, "bad.json:1:"); /* malformed JSON */
    expect_bad("{\"camera\": {\"eye\": \"here\", \"look_at\": [0,0,0]}}", NULL,
               "camera.eye"); /* type */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0], \"zoom\": 2}}", NULL,
               "camera.zoom"); /* unknown key */
    expect_bad(
        "{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"
        " \"objects\": [{\"shape\": \"mesh\", \"file\": \"nope.obj\", \"material\": \"m\"}]}",
        NULL, "nope.obj"); /* missing mesh */
    expect_bad("{\"camera\": {\"eye\": [0,0,1e400], \"look_at\": [0,0,0]}}", NULL,
               "finite"); /* non-finite */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"
               " \"objects\": [{\"shape\": \"box\", \"size\": [1, -1, 1], \"material\": \"m\"}]}",
               NULL, "objects[0].size[1]"); /* negative size */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"
               " \"objects\": []}",
               NULL, "empty"); /* empty scene */
    expect_bad(
        "{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]}, \"materials\": {\"m\": {}},"
        " \"objects\": [{\"shape\": \"revolution\", \"segments\": 100000000, \"material\": \"m\","
        " \"profile\": [[0, 0], [1, 1]]}]}",
        NULL, "segments"); /* absurd count */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]},"
               " \"render\": {\"shadow_by_weight\": 1}}",
               NULL, "render.shadow_by_weight"); /* a number for a boolean */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]},"
               " \"render\": {\"penumbra_feelers\": 3}}",
               NULL, "render.penumbra_feelers"); /* not a power of two */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]},"
               " \"render\": {\"aa_reconstruct\": \"mean\"}}",
               NULL, "render.aa_reconstruct"); /* not a reconstruction */
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0]},"
               " \"render\": {\"aa\": 0.1, \"aa_max_level\": 2, \"aa_min_level\": 3}}",
               NULL, "render.aa_min_level"); /* below the deepest level */
    expect_bad(GOOD_SCENE, "--aa 0.1 --aa-max-level 1 --aa-min-level 2", "--aa-min-level");
    expect_bad(GOOD_SCENE, "--aa-min-level 1", "needs adaptive anti-aliasing");
    expect_bad(GOOD_SCENE, "--aa-reconstruct box", "--aa-reconstruct box");
    expect_bad(GOOD_SCENE, "--penumbra-feelers 6", "--penumbra-feelers 6");
    expect_bad(GOOD_SCENE, "--grid 0", "--grid");        /* bad option */
    expect_bad(GOOD_SCENE, "--grid 4:65", "SUB 1..64");  /* sub-grid too fine */
    expect_bad(GOOD_SCENE, "--width 100000", "--width"); /* absurd image size */
    /* unreadable mesh: the tests run as root, so a directory stands in for a file */
    char dirpath[512];
    snprintf(dirpath, sizeof dirpath, "%s/unreadable.obj", tu_tmpdir());
    mkdir(dirpath, 0755);
    expect_bad(MESH_SCENE("unreadable.obj"), NULL, "unreadable.obj");
    /* corrupt meshes: a binary PLY cut short, a PLY that announces 4 billion vertices */
    static const char ply_head[] = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"
                                   "property float x\nproperty float y\nproperty float z\n"
                                   "element face 1\nproperty list uchar int vertex_indices\n"
                                   "end_header\n";
    char plypath[512];
    snprintf(plypath, sizeof plypath, "%s/truncated.ply", tu_tmpdir());
    FILE *f = fopen(plypath, "wb");
    if (f) {
        static const float verts[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        fwrite(ply_head, 1, sizeof ply_head - 1, f);
        fwrite(verts, sizeof verts[0], 7, f); /* two floats and the face short */
        fclose(f);
    }
    expect_bad(MESH_SCENE("truncated.ply"), NULL, "truncated.ply");
    tu_write_file("huge.ply", "ply\nformat ascii 1.0\nelement vertex 4294967295\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "end_header\n0 0 0\n");
    expect_bad(MESH_SCENE("huge.ply"), NULL, "huge.ply");
    char out[4096];
    const char *scene = tu_write_file("good.json", GOOD_SCENE);
    char args[1024];
    snprintf(args, sizeof args, "%s -o %s/out.bmp", scene, tu_tmpdir());
    CHECK(vbcl(args, out, sizeof out) == 2 && strstr(out, "bmp"), "unknown image format: %s", out);
    snprintf(args, sizeof args, "%s/does-not-exist.json", tu_tmpdir());
    CHECK(vbcl(args, out, sizeof out) == 2 && strstr(out, "does-not-exist.json") &&
              strstr(out, "No such file"),
          "missing scene: %s", out);
}

/* A scene read through a pipe (issue 17): a named pipe and "-" are read exactly once (a
 * second open would wait forever); with "-" mesh paths start at the current directory. */
static void test_cli_scene_from_pipe(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = tu_write_file("piped.json", GOOD_SCENE);
    char cmd[4096], out[8192], img[512];
    snprintf(img, sizeof img, "%s/piped.png", tu_tmpdir());
    snprintf(cmd, sizeof cmd,
             "cd %s && rm -f fifo.json && mkfifo fifo.json && (cat %s > fifo.json &) && "
             "timeout 60 %s%s fifo.json -q -o %s",
             tu_tmpdir(), scene, tu_vbcl[0] == '/' ? "" : "\"$OLDPWD\"/", tu_vbcl, img);
    int rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0 && file_exists(img), "a named pipe renders (%d): %s", rc, out);
    /* "-": the mesh tri.obj is found in the current directory */
    tu_write_file("pipe_tri.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
    const char *mesh_scene = tu_write_file("pipe_mesh.json", MESH_SCENE("pipe_tri.obj"));
    remove(img);
    snprintf(cmd, sizeof cmd, "cd %s && timeout 60 %s%s - -q -o %s --width 8 --height 8 < %s",
             tu_tmpdir(), tu_vbcl[0] == '/' ? "" : "\"$OLDPWD\"/", tu_vbcl, img, mesh_scene);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0 && file_exists(img), "- with a relative mesh renders (%d): %s", rc, out);
    snprintf(cmd, sizeof cmd, "cat %s | timeout 60 %s /dev/stdin -q -o %s --width 8 --height 8",
             scene, tu_vbcl, img);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 0, "/dev/stdin from a pipe renders (%d): %s", rc, out);
    snprintf(cmd, sizeof cmd, "printf '{\"camera\": ' | timeout 60 %s - -o %s", tu_vbcl, img);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "<stdin>:1:12: JSON syntax error"), "bad scene on stdin: %s", out);
}

/* Every output path is checked before any work (issue 17): a missing directory for the
 * image, the --aa-map, the --aa-samples-map or a frame exits 2 naming the path as given,
 * writing nothing. */
static void test_cli_outputs_checked_first(void)
{
    const char *scene = tu_write_file("out_good.json", GOOD_SCENE);
    char args[2048], out[8192], img[512];
    snprintf(img, sizeof img, "%s/checked.png", tu_tmpdir());
    remove(img);
    snprintf(args, sizeof args, "%s -o %s --aa 0.1 --aa-map %s/nodir/map.png", scene, img,
             tu_tmpdir());
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "nodir/map.png: cannot write there") && !file_exists(img),
          "missing --aa-map directory: nothing rendered (%d): %s", rc, out);
    snprintf(args, sizeof args, "%s -o %s --aa 0.1 --aa-samples-map %s/nodir/spp.png", scene, img,
             tu_tmpdir());
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "nodir/spp.png: cannot write there") && !file_exists(img),
          "missing --aa-samples-map directory: nothing rendered (%d): %s", rc, out);
    snprintf(args, sizeof args, "%s -o %s/nodir/x.png", scene, tu_tmpdir());
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "nodir/x.png: cannot write there") && !strstr(out, ".tmp"),
          "missing -o directory named as given (%d): %s", rc, out);
    expect_bad(GOOD_SCENE, "-o /proc/nodir/x.exr", "/proc/nodir/x.exr");
}

/* An animation whose frame 1 is out of range fails before frame 0 is written, naming the
 * track and the frame (issue 17). */
static void test_cli_animation_checked_first(void)
{
    const char *scene = tu_write_file(
        "anim_bad.json",
        "{\"image\": {\"width\": 8, \"height\": 8},"
        " \"camera\": {\"eye\": [0, 0, 5], \"look_at\": [0, 0, 0]},"
        " \"materials\": {\"m\": {}}, \"objects\": [{\"shape\": \"sphere\", \"material\": \"m\"}],"
        " \"animation\": {\"frames\": 2, \"tracks\": [{\"target\": \"camera.fov\","
        "   \"keys\": [[0, 40], [1, 400]]}]}}");
    char args[2048], out[8192], path[512];
    snprintf(path, sizeof path, "%s/animbad_0.png", tu_tmpdir());
    snprintf(args, sizeof args, "%s -o %s/animbad_#.png", scene, tu_tmpdir());
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "animation.tracks[0] at frame 1: camera.fov: 400 is out of range"),
          "frame 1 named (%d): %s", rc, out);
    CHECK(!file_exists(path), "frame 0 not written");
}

/* A mesh must be a regular file of at most 1 GiB (issue 17): a link to /dev/zero grew
 * memory until the machine ran out; a pipe would wait forever. */
static void test_cli_mesh_files_capped(void)
{
    char path[512], cmd[1024];
    snprintf(path, sizeof path, "%s/zero.obj", tu_tmpdir());
    remove(path);
    if (symlink("/dev/zero", path)) CHECK(0, "symlink %s", path);
    snprintf(cmd, sizeof cmd,
             "cd %s && rm -f fifo.obj && mkfifo fifo.obj && truncate -s 1100M big.obj",
             tu_tmpdir());
    CHECK(tu_run(cmd, NULL, 0) == 0, "mkfifo and truncate");
    expect_bad(MESH_SCENE("zero.obj"), NULL, "zero.obj: not a regular file");
    expect_bad(MESH_SCENE("fifo.obj"), NULL, "fifo.obj: not a regular file");
    expect_bad(MESH_SCENE("big.obj"), NULL,
               "big.obj: 1153433600 bytes, more than the limit of 1 GiB");
}

/* Control characters in a file name, an argument or a key appear as \xNN, and a huge
 * value is cut: every message stays one harmless line (issue 17). */
static void test_cli_messages_escaped(void)
{
    char cmd[2048], out[8192];
    snprintf(cmd, sizeof cmd, "%s \"$(printf '%s/a\\nb\\033[31m.json')\"", tu_vbcl, tu_tmpdir());
    int rc = tu_run(cmd, out, sizeof out);
    char *nl = strchr(out, '\n');
    CHECK(rc == 2 && strstr(out, "a\\x0ab\\x1b[31m.json"), "file name escaped (%d): %s", rc, out);
    CHECK(nl && nl[1] == 0 && !strchr(out, '\033'), "one line, no raw ESC: %s", out);
    snprintf(cmd, sizeof cmd, "%s x.json --width \"$(head -c 100000 /dev/zero | tr '\\0' 9)\"",
             tu_vbcl);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--width 999") && strstr(out, "...") && strlen(out) < 300,
          "a 100,000-character value is cut (%d, %zu characters): %.300s", rc, strlen(out), out);
    snprintf(cmd, sizeof cmd, "%s x.json \"$(printf -- '--e\\033]0;x\\007')\"", tu_vbcl);
    rc = tu_run(cmd, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--e\\x1b]0;x\\x07") && !strchr(out, '\033'),
          "unknown option escaped (%d): %s", rc, out);
    expect_bad("{\"camera\": {\"eye\": [0,0,1], \"look_at\": [0,0,0], \"z\\u001b[2J\": 2}}", NULL,
               "camera.z\\x1b[2J");
}

/* --stats-json holds the numbers --stats prints; a path it cannot write fails the run
 * before rendering (missing directory) or after it (exit 1), leaving no file either way. */
static void test_cli_stats_json(void)
{
    if (!tu_device()) {
        th_skip("no OpenCL device");
        return;
    }
    const char *scene = tu_write_file("stats.json", GOOD_SCENE);
    char out[16384], args[2048], json[512], img[512];
    snprintf(json, sizeof json, "%s/stats-out.json", tu_tmpdir());
    snprintf(img, sizeof img, "%s/stats.png", tu_tmpdir());
    remove(json);
    snprintf(args, sizeof args, "%s -o %s --aa 0.05 --stats --stats-json %s", scene, img, json);
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 0, "render with --stats --stats-json exits 0 (%d): %s", rc, out);
    unsigned long long primary = 0, refine = 0, shadow = 0, total = 0;
    unsigned tris = 0, cells = 0, spp_max = 0;
    double spp = 0;
    const char *l;
    int got = 0;
    if ((l = strstr(out, "\nrays        primary ")))
        got += sscanf(l, "\nrays primary %llu, refinement %llu, shadow %llu", &primary, &refine,
                      &shadow) == 3;
    if ((l = strstr(out, "unneeded: no BRDF response), total ")))
        got += sscanf(l, "unneeded: no BRDF response), total %llu", &total) == 1;
    if ((l = strstr(out, " objects, "))) got += sscanf(l, " objects, %u triangles", &tris) == 1;
    if ((l = strstr(out, " cells ("))) {
        while (l > out && l[-1] != ' ') l--;
        got += sscanf(l, "%u", &cells) == 1;
    }
    if ((l = strstr(out, "\nsamples     ")))
        got += sscanf(l, "\nsamples %lf per pixel (mean), %u (max)", &spp, &spp_max) == 2;
    CHECK(got == 5, "the --stats text has every number (%d of 5): %s", got, out);
    CHECK(refine > 0 && spp > 1, "--aa 0.05 refines pixels (%llu, %g per pixel)", refine, spp);
    cJSON *doc = read_json(json);
    CHECK(doc != NULL, "%s parses as JSON", json);
    CHECK(json_num(doc, "rays", "total", NULL) == (double)total, "rays.total %g, text %llu",
          json_num(doc, "rays", "total", NULL), total);
    CHECK(json_num(doc, "rays", "primary", NULL) == (double)primary, "rays.primary %g, text %llu",
          json_num(doc, "rays", "primary", NULL), primary);
    CHECK(json_num(doc, "rays", "refinement", NULL) == (double)refine,
          "rays.refinement %g, text %llu", json_num(doc, "rays", "refinement", NULL), refine);
    CHECK(json_num(doc, "rays", "shadow", NULL) == (double)shadow, "rays.shadow %g, text %llu",
          json_num(doc, "rays", "shadow", NULL), shadow);
    CHECK(json_num(doc, "scene", "triangles", NULL) == tris, "scene.triangles %g, text %u",
          json_num(doc, "scene", "triangles", NULL), tris);
    CHECK(json_num(doc, "grid", "cells", NULL) == cells, "grid.cells %g, text %u",
          json_num(doc, "grid", "cells", NULL), cells);
    /* every kernel counter, under the group and key its VBCL_COUNTER_LIST entry gives */
    int counters = 0, found = 0;
#define CLI_COUNTER(name, index, field, group, key)                                                \
    counters++;                                                                                    \
    found += !isnan(json_num(doc, #group, key, NULL));
    VBCL_COUNTER_LIST(CLI_COUNTER)
#undef CLI_COUNTER
    CHECK(found == counters, "--stats-json has %d of the %d counters", found, counters);
    double mean = json_num(doc, "samples", "per_pixel_mean", NULL);
    CHECK(fabs(mean - spp) <= 0.005, "samples.per_pixel_mean %g, text %.2f", mean, spp);
    CHECK(json_num(doc, "samples", "per_pixel_max", NULL) == spp_max,
          "samples.per_pixel_max %g, text %u", json_num(doc, "samples", "per_pixel_max", NULL),
          spp_max);
    /* the wall times: the wait for OpenImageIO, the render and the write are parts of the
     * total that do not overlap; the text prints the wait as "image library" */
    double wait = json_num(doc, "time_ms", "image_wait", NULL);
    double render = json_num(doc, "time_ms", "render", NULL);
    double write = json_num(doc, "time_ms", "write", NULL);
    double whole = json_num(doc, "time_ms", "total", NULL);
    CHECK(wait >= 0 && render >= 0 && write >= 0 && wait + render + write <= whole + 0.5,
          "time_ms: image_wait %g + render %g + write %g within total %g", wait, render, write,
          whole);
    double wait_text = -1;
    if ((l = strstr(out, "| image library "))) sscanf(l, "| image library %lf ms", &wait_text);
    CHECK(fabs(wait_text - wait) <= 0.051, "the text's image library %g ms, time_ms.image_wait %g",
          wait_text, wait);
    cJSON_Delete(doc);
    /* -q and no --stats: nothing printed, the file still written */
    remove(json);
    snprintf(args, sizeof args, "%s -q -o %s --stats-json %s", scene, img, json);
    rc = vbcl(args, out, sizeof out);
    doc = read_json(json);
    CHECK(rc == 0 && out[0] == 0 && json_num(doc, "rays", "primary", NULL) == 24 * 16,
          "-q --stats-json writes the file alone (%d): %s", rc, out);
    cJSON_Delete(doc);
    /* a missing directory: exit 2 before rendering, neither file written */
    remove(img);
    snprintf(json, sizeof json, "%s/no-such-dir/stats.json", tu_tmpdir());
    snprintf(args, sizeof args, "%s -o %s --stats-json %s", scene, img, json);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "no-such-dir"), "missing directory: exit 2 (%d): %s", rc, out);
    CHECK(!file_exists(json) && !file_exists(img), "nothing written for a missing directory");
    /* a path that cannot be renamed onto (a directory): exit 1, no temporary file left */
    char dir[512];
    snprintf(dir, sizeof dir, "%s/statsdir", tu_tmpdir());
    mkdir(dir, 0755);
    snprintf(args, sizeof args, "%s -q -o %s --stats-json %s", scene, img, dir);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 1 && strstr(out, "statsdir"), "unwritable path: exit 1 (%d): %s", rc, out);
    CHECK(!tu_dir_has(tu_tmpdir(), ".statsdir.tmp"), "no temporary file left beside it");
}

/* What a user of another renderer types: the nearest valid key or option is suggested
 * (edit distance, and names other renderers use: ior, center, color), --option=value is
 * taken, and --help names vbcl texgen. */
static void test_cli_suggestions(void)
{
    static const struct {
        const char *key, *where, *near;
    } keys[] = {
        {"\"ior\": 1.5", "materials", "did you mean \"eta\"?"},
        {"\"color\": [1, 0, 0]", "materials", "did you mean \"diffuse\"?"},
        {"\"difuse\": [1, 0, 0]", "materials", "did you mean \"diffuse\"?"},
        {"\"center\": [2, 4, 3]", "lights", "did you mean \"centre\"?"},
        {"\"coluor\": [1, 1, 1]", "lights", "did you mean \"colour\"?"},
        {"\"zoom\": 2", "camera", NULL},
    };
    char text[2048];
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        const char *m =
            !strcmp(keys[i].where, "materials") ? keys[i].key : "\"diffuse\": [1, 1, 1]";
        const char *l = !strcmp(keys[i].where, "lights") ? keys[i].key : "\"centre\": [2, 4, 3]";
        const char *c = !strcmp(keys[i].where, "camera") ? keys[i].key : "\"fov\": 40";
        snprintf(text, sizeof text,
                 "{\"camera\": {\"eye\": [0, 1, 5], \"look_at\": [0, 0, 0], %s},\n"
                 " \"lights\": [{%s, \"flux\": 500}],\n"
                 " \"materials\": {\"m\": {%s}},\n"
                 " \"objects\": [{\"shape\": \"sphere\", \"material\": \"m\"}]}\n",
                 c, l, m);
        expect_bad(text, "", keys[i].near ? keys[i].near : "unknown key (expected one of");
    }
    char out[16384], args[1024];
    const char *scene = tu_write_file("suggest.json", GOOD_SCENE);
    snprintf(args, sizeof args, "%s --widht 8", scene);
    int rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "unknown option --widht: did you mean --width?"),
          "--widht: suggested (%d): %s", rc, out);
    snprintf(args, sizeof args, "%s --sead 3", scene);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "did you mean --seed?"), "--sead (%d): %s", rc, out);
    snprintf(args, sizeof args, "%s --zzzzzz 3", scene);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && !strstr(out, "did you mean"), "nothing near --zzzzzz (%d): %s", rc, out);
    char a[512], b[512];
    snprintf(a, sizeof a, "%s/eq_a.pfm", tu_tmpdir());
    snprintf(b, sizeof b, "%s/eq_b.pfm", tu_tmpdir());
    snprintf(args, sizeof args, "%s -q --width=12 --height=10 --seed=3 --output=%s", scene, a);
    CHECK(vbcl(args, out, sizeof out) == 0, "--option=value: %s", out);
    snprintf(args, sizeof args, "%s -q --width 12 --height 10 --seed 3 -o %s", scene, b);
    CHECK(vbcl(args, out, sizeof out) == 0, "--option value: %s", out);
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cmp %s %s", a, b);
    CHECK(tu_run(cmd, out, sizeof out) == 0, "--option=value is --option value: %s", out);
    snprintf(args, sizeof args, "%s --stats=yes", scene);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2 && strstr(out, "--stats takes no value"), "a flag with a value (%d): %s", rc,
          out);
    snprintf(args, sizeof args, "%s --width=", scene);
    rc = vbcl(args, out, sizeof out);
    CHECK(rc == 2, "--width= with no value: exit 2 (%d): %s", rc, out);
    rc = vbcl("--help", out, sizeof out);
    CHECK(rc == 0 && strstr(out, "vbcl texgen"), "--help names vbcl texgen");
}

void suite_cli(void)
{
    RUN_TEST(test_cli_help_and_usage);
    RUN_TEST(test_cli_suggestions);
    RUN_TEST(test_cli_image_plugin);
    th_group("program binaries"); /* the first compiles a program's binary, the others reuse it */
    RUN_TEST(test_cli_cache_pruned);
    RUN_TEST(test_cli_cache_binaries);
    RUN_TEST(test_cli_damaged_binary);
    th_group(NULL);
    RUN_TEST(test_cli_compile_notice);
    RUN_TEST(test_cli_list_devices);
    RUN_TEST(test_cli_renders_and_overrides);
    RUN_TEST(test_cli_bad_input_classes);
    RUN_TEST(test_cli_messages_escaped);
    RUN_TEST(test_cli_scene_from_pipe);
    RUN_TEST(test_cli_outputs_checked_first);
    RUN_TEST(test_cli_animation_checked_first);
    RUN_TEST(test_cli_mesh_files_capped);
    RUN_TEST(test_cli_frames);
    RUN_TEST(test_cli_fixed_feelers);
    RUN_TEST(test_cli_cone_test);
    RUN_TEST(test_cli_camera_tiles);
    RUN_TEST(test_cli_feelers_by_weight);
    RUN_TEST(test_cli_sample_shares);
    RUN_TEST(test_cli_stats_json);
}
