/* Small helpers every part of the engine shares: error reporting, files, hex, hashes and checked JSON reads.
 *
 * Errors are reported where they are found (`engine-c: FILE: WHERE: what is wrong — what to do`) and the
 * function returns false / NULL; callers unwind and free. Nothing is printed twice and nothing exits early,
 * so every Vulkan object is still destroyed and the validation layer can check for leaks. */
#ifndef ENGINE_UTIL_H
#define ENGINE_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <cjson/cJSON.h>

#if defined(__GNUC__)
#define PRINTF_LIKE(a, b) __attribute__((format(printf, a, b)))
#else
#define PRINTF_LIKE(a, b)
#endif

/* Prints `engine-c: <message>` and a newline on stderr; returns false so a caller can `return fail(...)`. */
bool fail(const char *fmt, ...) PRINTF_LIKE(1, 2);
/* Prints `engine-c: note: <message>` (something clamped or skipped that the picture may show). */
void note(const char *fmt, ...) PRINTF_LIKE(1, 2);

/* A malloc'd copy of `dir`/`rel` (rel as the manifest writes it: '/'-separated, relative). */
char *path_join(const char *dir, const char *rel);
/* The whole file, malloc'd (plus a NUL byte after it, so text can be parsed in place); NULL and a message. */
unsigned char *read_file(const char *path, size_t *size);
/* Writes `data` to `path` atomically: a temporary file beside it, then rename (a reader never sees half). */
bool write_file_atomic(const char *path, const void *data, size_t size);

/* Two hex digits a byte. Returns a malloc'd buffer of *size bytes, or NULL on a bad digit or odd length. */
unsigned char *hex_decode(const char *hex, size_t *size);
/* sha256 of `data` as 64 lowercase hex digits and a NUL (smpack_sha256 of pack.h does the hashing). */
void sha256_hex(const void *data, size_t size, char out[65]);
/* A file's sha256 against the manifest's: false with `engine-c: PATH: sha256 … is not …` on a mismatch. */
bool check_sha256(const char *path, const void *data, size_t size, const char *want);

/* `text` (`size` bytes) parsed as JSON; on a syntax error `FILE:LINE:COL: not valid JSON — HINT` and NULL. */
cJSON *json_parse_file(const char *file, const char *text, size_t size, const char *hint);

/* Where a JSON value came from, for messages: the file and what to do when it is wrong. */
typedef struct json_src {
    const char *file;  /* shown path, e.g. "out/example/manifest.json" */
    const char *hint;  /* e.g. "rebuild with `shadermatrix build SCENE --out DIR`" */
} json_src;

/* Checked reads: each prints `FILE: WHERE.KEY: missing or not a … — HINT` and returns NULL / false when the
 * member is absent or of another type. `where` names the object (`permutations[3].render_state`). */
const cJSON *j_obj(const json_src *src, const cJSON *obj, const char *key, const char *where);
const cJSON *j_arr(const json_src *src, const cJSON *obj, const char *key, const char *where);
const char *j_str(const json_src *src, const cJSON *obj, const char *key, const char *where);
bool j_num(const json_src *src, const cJSON *obj, const char *key, const char *where, double *out);
bool j_int(const json_src *src, const cJSON *obj, const char *key, const char *where, long lo, long hi, int *out);
bool j_bool(const json_src *src, const cJSON *obj, const char *key, const char *where, bool *out);
/* An array member of exactly `n` numbers into out[]. */
bool j_nums(const json_src *src, const cJSON *obj, const char *key, const char *where, double *out, int n);
/* `obj[key]` without complaint when absent (NULL); used for optional members. */
const cJSON *j_opt(const cJSON *obj, const char *key);
/* A message about a value: `FILE: WHERE: WHAT — HINT`; returns false. */
bool j_fail(const json_src *src, const char *where, const char *fmt, ...) PRINTF_LIKE(3, 4);

#endif
