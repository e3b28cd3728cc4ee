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

/* The most bytes of compiled kernels the cache keeps: $VBCL_CACHE_MAX_MB megabytes
 * (default CACHE_MAX_MB_DEFAULT; a value that is not a positive whole number is refused
 * with a warning, once per run, and the default kept). */
#define CACHE_MAX_MB_DEFAULT 256
uint64_t cache_max_bytes(void);

/* $VBCL_CACHE_BINARIES: 1 (store program binaries on every driver), 0 (on none), or -1
 * when unset or another value, which is named with a warning, once per run. */
int cache_binaries_setting(void);

/* Marks path as just used (its modification time now), so that cache_prune keeps it
 * longer than the files not used since. */
void cache_touch(const char *path);

/* Keeps the files of dir whose names end in suffix within max_bytes in all, removing the
 * least recently used first (oldest modification time), never the file `keep` (a path,
 * or NULL). Returns how many it removed. */
int cache_prune(const char *dir, const char *suffix, uint64_t max_bytes, const char *keep);

/* FNV-1a over the bytes of s, continuing from h (start with CACHE_HASH_SEED). */
#define CACHE_HASH_SEED 1469598103934665603ull
uint64_t cache_hash(uint64_t h, const char *s);

/* Seals the cache entry at path: path + ".sum" gets the FNV-1a hash and the size of its
 * bytes (written whole, fileio.h). Returns 0, or -1 with a message in err. */
int cache_seal(const char *path, char *err, size_t errlen);

/* Whether the entry at path is whole: 0 when its bytes match its seal, else -1 with the
 * reason in why ("no checksum beside it", "12 bytes where 4096 were written", "its
 * checksum differs"). */
int cache_check_seal(const char *path, char *why, size_t n);

/* Removes the entry at path and its seal. */
void cache_remove(const char *path);

#endif
