/* testutil.h — what the test suites share: the vbcl binary under test, the OpenCL device
 * (opened once), running commands, and temporary files. */
#ifndef VBCL_TESTUTIL_H
#define VBCL_TESTUTIL_H

#include <stddef.h>

#include "clu.h"

/* Path of the vbcl binary the command-line tests run. */
extern const char *tu_vbcl;

/* The default OpenCL device, opened on first use; NULL (with a message) if none. */
VbDevice *tu_device(void);

/* Runs a shell command, capturing stdout and stderr together into out (may be NULL).
 * Returns the exit status, or -1 if it could not run. */
int tu_run(const char *cmd, char *out, size_t outlen);

/* A fresh temporary directory for this test run (created once, removed at exit). */
const char *tu_tmpdir(void);

/* Writes text to dir/name and returns the full path in a static buffer ring. */
const char *tu_write_file(const char *name, const char *text);

/* Reads up to n - 1 bytes of the file at path into buf, NUL-terminated (empty when it
 * cannot be opened); returns buf. */
char *tu_read_file(const char *path, char *buf, size_t n);

/* Runs vbcl on the scene file at scene_path with args, writing to an output file that
 * already holds an older image, and checks what every refusal of bad input does: exit 2,
 * one line that contains needle, the older file untouched. */
void tu_expect_refused(const char *scene_path, const char *args, const char *needle);

/* Whether directory dir holds a file whose name contains part. */
int tu_dir_has(const char *dir, const char *part);

/* Suites, one per test file. */
void suite_mesh(void);
void suite_grid_build(void);
void suite_scene(void);
void suite_objects(void);
void suite_texgen(void);
void suite_cli(void);
void suite_kernels(void);
void suite_optics(void);
void suite_patterns(void);
void suite_stability(void);
void suite_render(void);
void suite_aa(void);
void suite_aa_map(void);
void suite_dispersion(void);
void suite_structure(void);
void suite_scale(void);
void suite_faults(void);
void suite_frame(void);
void suite_crop(void);
void suite_environment(void);

/* A test that runs probe kernels (tests/fixture.c): with workers (vbcl-tests -j), all such
 * tests run in one worker, which compiles each probe kernel once at its first launch while
 * the others run the rest (th_group). */
#define RUN_PROBE_TEST(fn)                                                                         \
    do {                                                                                           \
        th_group("probe kernels");                                                                 \
        th_run(#fn, fn);                                                                           \
        th_group(NULL);                                                                            \
    } while (0)

#endif
