/* cache.c — the cache directory and the hash that keys its files. */
#include "cache.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
