/* See util.h. */
#include "util.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <shadermatrix/pack.h>

bool fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("engine-c: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return false;
}

void note(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("engine-c: note: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

char *path_join(const char *dir, const char *rel)
{
    size_t a = strlen(dir), b = strlen(rel);
    char *out = malloc(a + b + 2);
    if (!out)
        return NULL;
    memcpy(out, dir, a);
    size_t at = a;
    if (a && dir[a - 1] != '/')
        out[at++] = '/';
    memcpy(out + at, rel, b + 1);
    return out;
}

unsigned char *read_file(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fail("%s: cannot open (%s) — check the path", path, strerror(errno));
        return NULL;
    }
    unsigned char *data = NULL;
    long n = -1;
    if (fseek(f, 0, SEEK_END) == 0)
        n = ftell(f);
    if (n < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fail("%s: cannot read (%s) — give a regular file", path, strerror(errno));
        fclose(f);
        return NULL;
    }
    data = malloc((size_t)n + 1);
    if (!data) {
        fail("%s: out of memory for %ld bytes", path, n);
        fclose(f);
        return NULL;
    }
    if (fread(data, 1, (size_t)n, f) != (size_t)n) {
        fail("%s: short read (%s) — check the file", path, strerror(errno));
        free(data);
        fclose(f);
        return NULL;
    }
    fclose(f);
    data[n] = 0;
    *size = (size_t)n;
    return data;
}

bool write_file_atomic(const char *path, const void *data, size_t size)
{
    size_t n = strlen(path);
    char *tmp = malloc(n + 16);
    if (!tmp)
        return fail("%s: out of memory", path);
    snprintf(tmp, n + 16, "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    bool ok = f != NULL;
    if (ok)
        ok = fwrite(data, 1, size, f) == size;
    if (f && fclose(f) != 0)
        ok = false;
    if (ok && rename(tmp, path) != 0)
        ok = false;
    if (!ok) {
        fail("%s: cannot write (%s) — check that its folder exists and is writable", path, strerror(errno));
        remove(tmp);
    }
    free(tmp);
    return ok;
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

unsigned char *hex_decode(const char *hex, size_t *size)
{
    size_t n = strlen(hex);
    if (n % 2)
        return NULL;
    unsigned char *out = malloc(n / 2 + 1);  /* +1: a zero-length block is still a valid pointer */
    if (!out)
        return NULL;
    for (size_t i = 0; i < n / 2; i++) {
        int hi = hex_digit(hex[2 * i]), lo = hex_digit(hex[2 * i + 1]);
        if (hi < 0 || lo < 0) {
            free(out);
            return NULL;
        }
        out[i] = (unsigned char)(hi << 4 | lo);
    }
    *size = n / 2;
    return out;
}

void sha256_hex(const void *data, size_t size, char out[65])
{
    unsigned char digest[32];
    smpack_sha256(data, size, digest);
    for (int i = 0; i < 32; i++)
        snprintf(out + 2 * i, 3, "%02x", digest[i]);
}

bool check_sha256(const char *path, const void *data, size_t size, const char *want)
{
    char got[65];
    sha256_hex(data, size, got);
    if (strcmp(got, want) != 0)
        return fail("%s: sha256 %.12s… is not the listed %.12s… (the file changed after it was written) — build "
                    "or export again", path, got, want);
    return true;
}

/* ------------------------------------------------------------------ checked JSON */

bool j_fail(const json_src *src, const char *where, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "engine-c: %s: %s: ", src->file, where);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, " — %s\n", src->hint);
    va_end(ap);
    return false;
}

const cJSON *j_opt(const cJSON *obj, const char *key)
{
    return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

static const cJSON *member(const json_src *src, const cJSON *obj, const char *key, const char *where,
                           cJSON_bool (*is)(const cJSON *), const char *kind)
{
    const cJSON *v = j_opt(obj, key);
    if (!v || !is(v)) {
        fprintf(stderr, "engine-c: %s: %s.%s: %s — %s\n", src->file, where, key,
                v ? kind : "missing", src->hint);
        return NULL;
    }
    return v;
}

const cJSON *j_obj(const json_src *src, const cJSON *obj, const char *key, const char *where)
{
    return member(src, obj, key, where, cJSON_IsObject, "not an object");
}

const cJSON *j_arr(const json_src *src, const cJSON *obj, const char *key, const char *where)
{
    return member(src, obj, key, where, cJSON_IsArray, "not an array");
}

const char *j_str(const json_src *src, const cJSON *obj, const char *key, const char *where)
{
    const cJSON *v = member(src, obj, key, where, cJSON_IsString, "not a string");
    return v ? v->valuestring : NULL;
}

bool j_num(const json_src *src, const cJSON *obj, const char *key, const char *where, double *out)
{
    const cJSON *v = member(src, obj, key, where, cJSON_IsNumber, "not a number");
    if (v)
        *out = v->valuedouble;
    return v != NULL;
}

bool j_int(const json_src *src, const cJSON *obj, const char *key, const char *where, long lo, long hi, int *out)
{
    double d;
    if (!j_num(src, obj, key, where, &d))
        return false;
    /* the range first: converting a double outside long's range (1e300 in a crafted file) is undefined */
    if (!(d >= (double)lo && d <= (double)hi) || d != (double)(long)d) {
        char at[512];
        snprintf(at, sizeof at, "%s.%s", where, key);
        return j_fail(src, at, "%g is not a whole number from %ld to %ld", d, lo, hi);
    }
    *out = (int)d;
    return true;
}

bool j_bool(const json_src *src, const cJSON *obj, const char *key, const char *where, bool *out)
{
    const cJSON *v = member(src, obj, key, where, cJSON_IsBool, "not true or false");
    if (v)
        *out = cJSON_IsTrue(v);
    return v != NULL;
}

bool j_nums(const json_src *src, const cJSON *obj, const char *key, const char *where, double *out, int n)
{
    const cJSON *a = j_arr(src, obj, key, where);
    if (!a)
        return false;
    char at[512];
    snprintf(at, sizeof at, "%s.%s", where, key);
    if (cJSON_GetArraySize(a) != n)
        return j_fail(src, at, "%d numbers, not %d", cJSON_GetArraySize(a), n);
    int i = 0;
    const cJSON *x;
    cJSON_ArrayForEach(x, a) {
        if (!cJSON_IsNumber(x))
            return j_fail(src, at, "item %d is not a number", i);
        out[i++] = x->valuedouble;
    }
    return true;
}

/* `text` parsed as JSON; on a syntax error `FILE:LINE:COL: not valid JSON`. */
cJSON *json_parse_file(const char *file, const char *text, size_t size, const char *hint)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (root)
        return root;
    int line = 1, col = 1;
    const char *at = end ? end : cJSON_GetErrorPtr();
    for (const char *p = text; at && p < at && p < text + size; p++) {
        if (*p == '\n') {
            line++;
            col = 1;
        } else {
            col++;
        }
    }
    fail("%s:%d:%d: not valid JSON — %s", file, line, col, hint);
    return NULL;
}

