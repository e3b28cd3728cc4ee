/* shim.c — libvbcl_fault.so, an LD_PRELOAD library for test_faults.c: fsync, the step of
 * every file write just before its rename (host/util/fileio.c), fails or is interrupted
 * by a signal, for files whose path contains $VBCL_FAULT_PATH, as $VBCL_FAULT says:
 * "EIO" or "ENOSPC" (fsync fails with that error), or "TERM", "INT", "HUP" (the process
 * gets that signal). Every other fsync is the C library's. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dlfcn.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int fault_here(int fd)
{
    const char *part = getenv("VBCL_FAULT_PATH");
    char link[64], path[4096];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    ssize_t n = readlink(link, path, sizeof path - 1);
    if (!part || n <= 0) return 0;
    path[n] = 0;
    return strstr(path, part) != NULL;
}

int fsync(int fd)
{
    const char *fault = getenv("VBCL_FAULT");
    if (fault && fault_here(fd)) {
        static const struct {
            const char *name;
            int sig, err;
        } faults[] = {{"EIO", 0, EIO},
                      {"ENOSPC", 0, ENOSPC},
                      {"TERM", SIGTERM, 0},
                      {"INT", SIGINT, 0},
                      {"HUP", SIGHUP, 0}};
        for (size_t i = 0; i < sizeof faults / sizeof faults[0]; i++) {
            if (strcmp(fault, faults[i].name)) continue;
            if (faults[i].sig) {
                raise(faults[i].sig);
                break; /* a handled signal returns here: the write goes on */
            }
            errno = faults[i].err;
            return -1;
        }
    }
    int (*real)(int) = (int (*)(int))dlsym(RTLD_NEXT, "fsync");
    return real ? real(fd) : 0;
}
