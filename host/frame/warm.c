/* warm.c — vbcl --warm-cache: a tiny built-in scene of each program class rendered through
 * renderer_init, whose first launches compile every kernel the class runs. */
#include "warm.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "kernel_features.h"
#include "render.h"
#include "scene.h"

/* One scene per program class (kernel_features.h): the features it has pick the class, and
 * the kernels it runs are every kernel of the class (the tree kernels with transparency,
 * the band kernel with dispersion; the film kernels in all). */
static const char *const warm_scenes[PROGRAM_COUNT] = {
    [PROGRAM_OPAQUE] =
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"eye\": [0, 0, 4], "
        "\"look_at\": [0, 0, 0]}, \"lights\": [{\"centre\": [2, 2, 4], \"radius\": 0.5, \"flux\": "
        "100}], "
        "\"materials\": {\"paint\": {\"diffuse\": [0.8, 0.2, 0.2], \"specular\": [0.5, 0.5, "
        "0.5]}}, "
        "\"objects\": [{\"shape\": \"sphere\", \"material\": \"paint\"}]}",
    [PROGRAM_DIELECTRIC] =
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"eye\": [0, 0, 4], "
        "\"look_at\": [0, 0, 0]}, \"materials\": {\"glass\": {\"k_global\": 1, \"eta\": 1.5}}, "
        "\"objects\": [{\"shape\": \"sphere\", \"material\": \"glass\"}]}",
    [PROGRAM_DISPERSIVE] =
        "{\"image\": {\"width\": 8, \"height\": 8}, \"camera\": {\"eye\": [0, 0, 4], "
        "\"look_at\": [0, 0, 0]}, \"materials\": {\"flint\": {\"k_global\": 1, \"eta\": 1.62, "
        "\"dispersion\": {\"model\": \"sellmeier\", \"preset\": \"F2\"}}}, "
        "\"objects\": [{\"shape\": \"sphere\", \"material\": \"flint\"}]}",
};

/* Builds program p on device `index` of clu_list_devices, in a context of its own, through
 * renderer_init on the class's built-in scene. Returns 0, or 1 with a message in err. */
static int warm_one(int index, int p, int *how, char *err, size_t errlen)
{
    VbDevice dev;
    if (clu_device_open_index(index, &dev, err, errlen)) return 1;
    Scene s;
    char serr[512];
    int rc = 0;
    if (scene_load_text("<warm-cache>", warm_scenes[p], -1, &s, serr, sizeof serr)) {
        snprintf(err, errlen, "the built-in %s scene: %s", features_program_name(p), serr);
        clu_device_close(&dev);
        return 1;
    }
    Renderer r;
    RenderStats st;
    memset(&st, 0, sizeof st);
    if (renderer_init(&r, &dev, &s, NULL, &st, err, errlen)) {
        rc = 1;
    } else {
        if (st.program != p) {
            snprintf(err, errlen, "the built-in %s scene ran the %s program",
                     features_program_name(p), features_program_name(st.program));
            rc = 1;
        }
        *how = st.build_cached;
        renderer_release(&r);
    }
    scene_free(&s);
    clu_device_close(&dev);
    return rc;
}

/* Worker w of `workers`: opens the devices spec names (OpenCL is started in each worker
 * process, never in the parent) and builds its share of the list (programs largest first,
 * then devices). Returns 0 or 1 (after a message). */
static int warm_worker(const char *spec, int w, int workers, int quiet)
{
    int picks[CLU_MAX_DEVICES];
    char err[1024];
    int ndev = clu_device_pick(spec, picks, CLU_MAX_DEVICES, err, sizeof err);
    if (ndev < 0) {
        fprintf(stderr, "vbcl: %s\n", err);
        return 1;
    }
    int njobs = ndev * PROGRAM_COUNT, rc = 0;
    for (int j = 0; j < njobs && !rc; j++) {
        /* dealt out back and forth (0 1 1 0 0 1 ...): the largest programs come first, so
         * a worker that gets one of them gets one of the smallest too */
        int round = j / workers, at = j % workers;
        if ((round % 2 ? workers - 1 - at : at) != w) continue;
        int p = PROGRAM_COUNT - 1 - j / ndev, d = picks[j % ndev], how = CLU_BUILT;
        double t0 = clu_now_ms();
        rc = warm_one(d, p, &how, err, sizeof err);
        if (rc)
            fprintf(stderr, "vbcl: warm-cache: %s kernels on device %d: %s\n",
                    features_program_name(p), d, err);
        else if (!quiet)
            fprintf(stderr, "vbcl: warm-cache: %s kernels on device %d: %s in %.1f s\n",
                    features_program_name(p), d, clu_build_how(how), (clu_now_ms() - t0) * 1e-3);
    }
    return rc;
}

int warm_cache(const char *spec, int jobs, int quiet)
{
    double t0 = clu_now_ms();
    if (jobs < 1) jobs = 1;
    if (jobs > PROGRAM_COUNT * CLU_MAX_DEVICES) jobs = PROGRAM_COUNT * CLU_MAX_DEVICES;
    if (!quiet)
        fprintf(stderr,
                "vbcl: warm-cache: compiling the %d kernel programs for each device, %d at a "
                "time; 1.5 - 2 minutes on 2 cores the first time, then renders start at once\n",
                PROGRAM_COUNT, jobs);
    fflush(stderr);
    pid_t pid[PROGRAM_COUNT * CLU_MAX_DEVICES];
    int started = 0, rc = 0;
    for (int w = 1; w < jobs; w++) {
        pid_t c = fork();
        if (c == 0) _exit(warm_worker(spec, w, jobs, quiet));
        if (c < 0) break; /* fewer workers: this process takes the rest below */
        pid[started++] = c;
    }
    /* a worker no child could be forked for runs here, after worker 0's jobs */
    for (int w = started + 1; w < jobs; w++) rc |= warm_worker(spec, w, jobs, quiet);
    rc |= warm_worker(spec, 0, jobs, quiet);
    for (int i = 0; i < started; i++) {
        int status = 0;
        while (waitpid(pid[i], &status, 0) < 0 && errno == EINTR) {
        }
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) rc = 1;
    }
    if (!rc && !quiet)
        fprintf(stderr, "vbcl: warm-cache: every program ready in %.1f s\n",
                (clu_now_ms() - t0) * 1e-3);
    return rc;
}
