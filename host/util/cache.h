/* cache.h — vbcl's cache directory (compiled kernels, generated textures) and the hash
 * that names the files in it. */
#ifndef VBCL_CACHE_H
#define VBCL_CACHE_H

#include <stddef.h>
#include <stdint.h>

/* The cache directory, or its subdirectory sub (may be NULL), created if needed:
 * $VBCL_CACHE_DIR, else $XDG_CACHE_HOME/vbcl, else $HOME/.cache/vbcl. Returns buf, or
 * NULL when VBCL_CACHE_DIR is "off" or the directory cannot be made. */
const char *cache_dir(const char *sub, char *buf, size_t n);

/* FNV-1a over the bytes of s, continuing from h (start with CACHE_HASH_SEED). */
#define CACHE_HASH_SEED 1469598103934665603ull
uint64_t cache_hash(uint64_t h, const char *s);

#endif
