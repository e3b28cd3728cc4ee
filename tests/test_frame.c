/* test_frame.c — one scene at every scale and position (issue 53): a glass sphere with
 * absorption and a volume texture over a floor, under one light, scaled by 1e-6 ... 1e6
 * and moved by up to 1e5 along each axis, renders within RMS 1e-3 of the unit scene, no
 * value off by more than 0.05, and its ray-tree counters within 0.5%
 * (scripts/frame_check.py renders and compares; docs/architecture.md, "Scale"). One test a
 * case; before the scene's frame (scene_frame_pick) every case but scale 1e3 and 1e6
 * failed. */
#include <stdio.h>
#include <string.h>

#include "harness.h"
#include "testutil.h"

/* scripts/frame_check.py's report, run once for every case. */
static const char *frame_report(void)
{
    static char out[16384];
    static int ran;
    if (!ran) {
        char cmd[2048];
        snprintf(cmd, sizeof cmd, "timeout 600 python3 scripts/frame_check.py --vbcl %s", tu_vbcl);
        tu_run(cmd, out, sizeof out);
        ran = 1;
    }
    return out;
}

/* Checks the report's line for one case: "frame: NAME: ok ...". */
static void frame_case(const char *name)
{
    const char *out = frame_report();
    char key[128];
    snprintf(key, sizeof key, "frame: %s: ", name);
    const char *line = strstr(out, key);
    int n = line ? (int)strcspn(line, "\n") : 0;
    CHECK(line && !strncmp(line + strlen(key), "ok", 2), "%s: %.*s%s", name, n, line ? line : "",
          line ? "" : out);
}

#define FRAME_TEST(fn, name)                                                                       \
    static void fn(void)                                                                           \
    {                                                                                              \
        frame_case(name);                                                                          \
    }
FRAME_TEST(test_frame_scale_1e_6, "scale 1e-6")
FRAME_TEST(test_frame_scale_1e_3, "scale 1e-3")
FRAME_TEST(test_frame_scale_1e3, "scale 1e3")
FRAME_TEST(test_frame_scale_1e6, "scale 1e6")
FRAME_TEST(test_frame_moved_1e3_x, "moved 1e3 x")
FRAME_TEST(test_frame_moved_1e3_y, "moved 1e3 y")
FRAME_TEST(test_frame_moved_1e3_z, "moved 1e3 z")
FRAME_TEST(test_frame_moved_1e4_x, "moved 1e4 x")
FRAME_TEST(test_frame_moved_1e4_y, "moved 1e4 y")
FRAME_TEST(test_frame_moved_1e4_z, "moved 1e4 z")
FRAME_TEST(test_frame_moved_1e5_x, "moved 1e5 x")
FRAME_TEST(test_frame_moved_1e5_y, "moved 1e5 y")
FRAME_TEST(test_frame_moved_1e5_z, "moved 1e5 z")

void suite_frame(void)
{
    RUN_TEST(test_frame_scale_1e_6);
    RUN_TEST(test_frame_scale_1e_3);
    RUN_TEST(test_frame_scale_1e3);
    RUN_TEST(test_frame_scale_1e6);
    RUN_TEST(test_frame_moved_1e3_x);
    RUN_TEST(test_frame_moved_1e3_y);
    RUN_TEST(test_frame_moved_1e3_z);
    RUN_TEST(test_frame_moved_1e4_x);
    RUN_TEST(test_frame_moved_1e4_y);
    RUN_TEST(test_frame_moved_1e4_z);
    RUN_TEST(test_frame_moved_1e5_x);
    RUN_TEST(test_frame_moved_1e5_y);
    RUN_TEST(test_frame_moved_1e5_z);
}
