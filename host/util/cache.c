/* cache.c — the cache directory and the hash that keys its files. */
#include "cache.h"

#include "fileio.h"

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

/* The FNV-1a hash (cache_hash's, over bytes) and the size of the file at path; 0, or -1
 * when it cannot be read. */
static int file_hash(const char *path, uint64_t *h, uint64_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    unsigned char buf[1 << 16];
    *h = CACHE_HASH_SEED;
    *size = 0;
    for (size_t k; (k = fread(buf, 1, sizeof buf, f)) > 0; *size += k)
        for (size_t i = 0; i < k; i++) *h = (*h ^ buf[i]) * 1099511628211ull;
    int bad = ferror(f);
    fclose(f);
    return bad ? -1 : 0;
}

/* The seal's path: path + ".sum". */
static int seal_path(const char *path, char *out, size_t n)
{
    int k = snprintf(out, n, "%s.sum", path);
    return k < 0 || (size_t)k >= n ? -1 : 0;
}

int cache_seal(const char *path, char *err, size_t errlen)
{
    char sum[4200], text[64];
    uint64_t h, size;
    if (seal_path(path, sum, sizeof sum) || file_hash(path, &h, &size)) {
        snprintf(err, errlen, "%s: cannot read it back to seal it", path);
        return -1;
    }
    int k = snprintf(text, sizeof text, "fnv1a64 %016llx %llu\n", (unsigned long long)h,
                     (unsigned long long)size);
    return file_write_whole(sum, text, (size_t)k, err, errlen);
}

int cache_check_seal(const char *path, char *why, size_t n)
{
    char sum[4200];
    unsigned long long want_h, want_size;
    uint64_t h, size;
    FILE *f = seal_path(path, sum, sizeof sum) ? NULL : fopen(sum, "r");
    int got = f ? fscanf(f, "fnv1a64 %16llx %llu", &want_h, &want_size) : 0;
    if (f) fclose(f);
    if (got != 2) {
        snprintf(why, n, "no checksum beside it");
        return -1;
    }
    if (file_hash(path, &h, &size)) {
        snprintf(why, n, "it cannot be read");
        return -1;
    }
    if (size != want_size) {
        snprintf(why, n, "%llu bytes where %llu were written", (unsigned long long)size, want_size);
        return -1;
    }
    if (h != want_h) {
        snprintf(why, n, "its checksum differs");
        return -1;
    }
    return 0;
}

void cache_remove(const char *path)
{
    char sum[4200];
    remove(path);
    if (!seal_path(path, sum, sizeof sum)) remove(sum);
}
