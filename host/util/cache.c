/* cache.c — the cache directory and the hash that keys its files. */
#include "cache.h"

#include <dirent.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <utime.h>

const char *cache_dir(const char *sub, char *buf, size_t n)
{
    const char *env = getenv("VBCL_CACHE_DIR");
    if (env && strcmp(env, "off") == 0) return NULL;
    int len;
    if (env && *env) {
        len = snprintf(buf, n, "%s", env);
    } else {
        const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
        if (xdg && *xdg)
            len = snprintf(buf, n, "%s/vbcl", xdg);
        else if (home && *home)
            len = snprintf(buf, n, "%s/.cache/vbcl", home);
        else
            return NULL;
    }
    if (sub && len >= 0 && (size_t)len < n) len += snprintf(buf + len, n - (size_t)len, "/%s", sub);
    if (len < 0 || (size_t)len >= n) return NULL;
    /* create each component */
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        mkdir(buf, 0755);
        *p = '/';
    }
    if (mkdir(buf, 0755) != 0 && errno != EEXIST) return NULL;
    return buf;
}

uint64_t cache_hash(uint64_t h, const char *s)
{
    for (; *s; s++) {
        h ^= (unsigned char)*s;
        h *= 1099511628211ull;
    }
    return h ^ 0xff;
}

static pthread_once_t cache_max_once = PTHREAD_ONCE_INIT;
static uint64_t cache_max;

/* Reads VBCL_CACHE_MAX_MB into cache_max, once per run: a bad value is named once, however
 * many devices build the program. */
static void cache_max_read(void)
{
    cache_max = (uint64_t)CACHE_MAX_MB_DEFAULT << 20;
    const char *env = getenv("VBCL_CACHE_MAX_MB");
    if (!env || !*env) return;
    char *end;
    errno = 0;
    unsigned long long mb = strtoull(env, &end, 10);
    if (errno || *end || mb == 0 || mb > (1ull << 40) || env[0] == '-')
        fprintf(stderr,
                "vbcl: VBCL_CACHE_MAX_MB=\"%s\" is not a positive whole number of megabytes; "
                "keeping the cache within %d MB\n",
                env, CACHE_MAX_MB_DEFAULT);
    else
        cache_max = (uint64_t)mb << 20;
}

uint64_t cache_max_bytes(void)
{
    pthread_once(&cache_max_once, cache_max_read);
    return cache_max;
}

static pthread_once_t cache_binaries_once = PTHREAD_ONCE_INIT;
static int cache_binaries = -1;

static void cache_binaries_read(void)
{
    const char *env = getenv("VBCL_CACHE_BINARIES");
    if (!env || !*env) return;
    if (!strcmp(env, "0") || !strcmp(env, "1"))
        cache_binaries = env[0] == '1';
    else
        fprintf(stderr, "vbcl: VBCL_CACHE_BINARIES=\"%s\" is not 0 or 1; keeping the default\n",
                env);
}

int cache_binaries_setting(void)
{
    pthread_once(&cache_binaries_once, cache_binaries_read);
    return cache_binaries;
}

void cache_touch(const char *path)
{
    utime(path, NULL); /* a cache file not marked is only pruned sooner */
}

typedef struct CacheFile {
    char name[256];
    uint64_t bytes;
    struct timespec mtime;
} CacheFile;

static int cache_file_older(const void *a, const void *b)
{
    const struct timespec *x = &((const CacheFile *)a)->mtime, *y = &((const CacheFile *)b)->mtime;
    if (x->tv_sec != y->tv_sec) return x->tv_sec < y->tv_sec ? -1 : 1;
    return (x->tv_nsec > y->tv_nsec) - (x->tv_nsec < y->tv_nsec);
}

int cache_prune(const char *dir, const char *suffix, uint64_t max_bytes, const char *keep)
{
    DIR *d = opendir(dir);
    if (!d) return 0;
    CacheFile *files = NULL;
    size_t n = 0, cap = 0, slen = strlen(suffix);
    uint64_t total = 0;
    char path[4096];
    for (struct dirent *e; (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len < slen || len >= sizeof files->name || strcmp(e->d_name + len - slen, suffix))
            continue;
        struct stat st;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (stat(path, &st) || !S_ISREG(st.st_mode)) continue;
        if (n == cap) {
            CacheFile *grown = realloc(files, sizeof *files * (cap = cap ? 2 * cap : 64));
            if (!grown) break;
            files = grown;
        }
        memcpy(files[n].name, e->d_name, len + 1);
        files[n].bytes = (uint64_t)st.st_size;
        files[n].mtime = st.st_mtim;
        total += files[n++].bytes;
    }
    closedir(d);
    int removed = 0;
    if (files) qsort(files, n, sizeof *files, cache_file_older);
    for (size_t i = 0; i < n && total > max_bytes; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i].name);
        if (keep && strcmp(path, keep) == 0) continue;
        if (remove(path) == 0) {
            total -= files[i].bytes;
            removed++;
        }
    }
    free(files);
    return removed;
}
