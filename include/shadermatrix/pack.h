/* shadermatrix/pack.h: a single-header C99 reader of shadermatrix shader packs (`shadermatrix build --pack`).

   In exactly one C or C++ file of the program:
       #define SHADERMATRIX_PACK_IMPLEMENTATION
       #include "shadermatrix/pack.h"
   everywhere else include it without the define. It compiles as C99, C11 and C++17 and allocates nothing,
   except smpack_open_file's one buffer holding the file.

   Opening checks the whole pack, as the generator's reader does (generator/assemble/pack.py read_pack) and
   in its order: magic, version, reserved field, sizes, the metadata (canonical JSON) and its padding; per
   index entry its names, the index order, its offset and length in the blobs, its blob's sha256, one
   length per offset; then blobs contiguous with nothing after the last, and the pack key. A pack opens with
   every entry trustworthy, or is refused with a status and a message naming the defect and its byte or
   entry. No input makes it read outside the given bytes; integers are read byte by byte (little-endian),
   so the bytes need no alignment. Format: docs/guide/build.md#shader-packs; reader: docs/reference/pack-h.md. */
#ifndef SHADERMATRIX_PACK_H
#define SHADERMATRIX_PACK_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SMPACK_FORMAT_VERSION 1
#define SMPACK_HEADER_SIZE 56
#define SMPACK_ENTRY_SIZE 104
#define SMPACK_META_DEPTH 32 /* the deepest nesting of the metadata's JSON accepted (the top object is 1) */

typedef enum smpack_status {
    SMPACK_OK = 0,
    SMPACK_ERR_ARGUMENT,   /* a NULL pointer, a permutation/stage name too long, an entry index past the count */
    SMPACK_ERR_IO,         /* cannot open/read the file */
    SMPACK_ERR_NOMEM,      /* smpack_open_file could not allocate the file's buffer */
    SMPACK_ERR_TRUNCATED,  /* shorter than the header / than header + meta + index */
    SMPACK_ERR_MAGIC,      /* not "SMPACK\r\n" (also a file shorter than the magic) */
    SMPACK_ERR_VERSION,    /* a format version this reader does not read */
    SMPACK_ERR_HEADER,     /* reserved field not 0 */
    SMPACK_ERR_META,       /* metadata not the canonical JSON object of a pack, non-zero padding */
    SMPACK_ERR_INDEX,      /* a malformed name field (empty, a NUL inside, not ASCII) */
    SMPACK_ERR_ORDER,      /* index not sorted by (permutation, stage), or a repeat */
    SMPACK_ERR_BOUNDS,     /* an entry's offset/length outside the blobs */
    SMPACK_ERR_OVERLAP,    /* blobs overlap, leave a gap, or trailing bytes after the last */
    SMPACK_ERR_HASH,       /* a blob's sha256 does not match */
    SMPACK_ERR_KEY,        /* the pack key does not match meta + index */
    SMPACK_ERR_NOT_FOUND   /* smpack_find: no such entry */
} smpack_status;

typedef struct smpack_entry {
    char permutation[17];        /* NUL-terminated: 12-hex hash, "ubershader", or a depth unit's hash */
    char stage[9];               /* "vert", "frag" */
    unsigned char input_key[32]; /* the manifest entry's input_key, raw */
    unsigned char sha256[32];    /* of the blob, raw; checked at open */
    uint64_t offset, length;     /* the blob's bytes in the pack */
    const unsigned char *data;   /* points into the pack's bytes; `length` bytes (SPIR-V: a multiple of 4,
                                    NOT guaranteed 4-byte aligned in memory: copy before vkCreateShaderModule) */
} smpack_entry;

/* An open pack. Every field is read-only for the caller; read them through the functions below. */
typedef struct smpack {
    const unsigned char *data;   /* the pack's bytes (NULL when not open) */
    size_t size;
    uint32_t version, count;     /* format version, number of index entries */
    unsigned char key[32];       /* the pack key, raw (the manifest's "key" is its hex) */
    size_t meta_length, index_at, blobs_at;
    void *owned;                 /* what smpack_open_file allocated, freed by smpack_close */
    char error[256];             /* the last open's message, "" after a success */
} smpack;

/* Opens the `size` bytes at `data` as a pack, checking all of it. Nothing is copied: `data` must outlive the
   pack. SMPACK_OK, or the defect's status with its message in smpack_error(pack) and no entries in the pack;
   SMPACK_ERR_ARGUMENT when pack or data is NULL. */
smpack_status smpack_open_memory(smpack *pack, const void *data, size_t size);

/* Reads the file at `path` into one malloc'd buffer owned by the pack, then opens it as smpack_open_memory
   does. SMPACK_ERR_IO (message: the system's reason) or SMPACK_ERR_NOMEM before any check. The buffer is
   freed on failure, or by smpack_close. */
smpack_status smpack_open_file(smpack *pack, const char *path);

/* Frees what smpack_open_file read, and empties the pack. Safe on a refused or closed pack and on NULL. Close
   a pack before opening it again. */
void smpack_close(smpack *pack);

/* The last open's message: what is wrong and at which byte or entry ("" after a success). Never NULL. */
const char *smpack_error(const smpack *pack);

/* The enumerator's name, "SMPACK_ERR_HASH" for SMPACK_ERR_HASH; "SMPACK_ERR_UNKNOWN" for any other value. */
const char *smpack_status_name(smpack_status s);

/* Number of index entries (0 for a pack that is not open). */
uint32_t smpack_count(const smpack *pack);

/* Fills *out with entry i (0 <= i < smpack_count, in index order: sorted by permutation, then stage).
   SMPACK_ERR_ARGUMENT for a NULL pointer or i past the count. */
smpack_status smpack_entry_at(const smpack *pack, uint32_t i, smpack_entry *out);

/* Finds the entry of (permutation, stage) by binary search of the sorted index: SMPACK_OK and *out filled,
   SMPACK_ERR_NOT_FOUND, or SMPACK_ERR_ARGUMENT for a NULL pointer or a name longer than its field (16 and 8
   characters). `permutation` is the manifest's 12-hex "hash" (not the canonical id), or "ubershader". */
smpack_status smpack_find(const smpack *pack, const char *permutation, const char *stage, smpack_entry *out);

/* The metadata: canonical JSON (sorted keys, no spaces, ASCII), `*length` bytes, NOT NUL-terminated; NULL
   (and *length 0) for a pack that is not open. `length` may be NULL. */
const char *smpack_meta(const smpack *pack, size_t *length);

/* SHA-256 of `size` bytes at `data` into out (raw, 32 bytes): the hash every check of the pack uses. */
void smpack_sha256(const void *data, size_t size, unsigned char out[32]);

#ifdef __cplusplus
}
#endif
#endif /* SHADERMATRIX_PACK_H */

/* ------------------------------------------------------------------------------------- implementation */
#if defined(SHADERMATRIX_PACK_IMPLEMENTATION) && !defined(SHADERMATRIX_PACK_IMPLEMENTED)
#define SHADERMATRIX_PACK_IMPLEMENTED

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- SHA-256 (FIPS 180-4), streaming: the key is hashed from pieces without building its JSON */

typedef struct smpack_i_sha { uint32_t h[8]; unsigned char block[64]; size_t fill; uint64_t total; } smpack_i_sha;

static const uint32_t smpack_i_k[64] = {
    0x428a2f98u, 0x71374491u, 0xb5c0fbcfu, 0xe9b5dba5u, 0x3956c25bu, 0x59f111f1u, 0x923f82a4u, 0xab1c5ed5u,
    0xd807aa98u, 0x12835b01u, 0x243185beu, 0x550c7dc3u, 0x72be5d74u, 0x80deb1feu, 0x9bdc06a7u, 0xc19bf174u,
    0xe49b69c1u, 0xefbe4786u, 0x0fc19dc6u, 0x240ca1ccu, 0x2de92c6fu, 0x4a7484aau, 0x5cb0a9dcu, 0x76f988dau,
    0x983e5152u, 0xa831c66du, 0xb00327c8u, 0xbf597fc7u, 0xc6e00bf3u, 0xd5a79147u, 0x06ca6351u, 0x14292967u,
    0x27b70a85u, 0x2e1b2138u, 0x4d2c6dfcu, 0x53380d13u, 0x650a7354u, 0x766a0abbu, 0x81c2c92eu, 0x92722c85u,
    0xa2bfe8a1u, 0xa81a664bu, 0xc24b8b70u, 0xc76c51a3u, 0xd192e819u, 0xd6990624u, 0xf40e3585u, 0x106aa070u,
    0x19a4c116u, 0x1e376c08u, 0x2748774cu, 0x34b0bcb5u, 0x391c0cb3u, 0x4ed8aa4au, 0x5b9cca4fu, 0x682e6ff3u,
    0x748f82eeu, 0x78a5636fu, 0x84c87814u, 0x8cc70208u, 0x90befffau, 0xa4506cebu, 0xbef9a3f7u, 0xc67178f2u};

static uint32_t smpack_i_rotr(uint32_t x, unsigned n) { return (x >> n) | (x << (32u - n)); }

static void smpack_i_sha_block(uint32_t h[8], const unsigned char *p) {
    uint32_t w[64], a = h[0], b = h[1], c = h[2], d = h[3], e = h[4], f = h[5], g = h[6], k = h[7];
    unsigned t;
    for (t = 0; t < 16; t++)
        w[t] = ((uint32_t)p[4 * t] << 24) | ((uint32_t)p[4 * t + 1] << 16) | ((uint32_t)p[4 * t + 2] << 8) | p[4 * t + 3];
    for (t = 16; t < 64; t++) {
        uint32_t s0 = smpack_i_rotr(w[t - 15], 7) ^ smpack_i_rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
        uint32_t s1 = smpack_i_rotr(w[t - 2], 17) ^ smpack_i_rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
        w[t] = w[t - 16] + s0 + w[t - 7] + s1;
    }
    for (t = 0; t < 64; t++) {
        uint32_t t1 = k + (smpack_i_rotr(e, 6) ^ smpack_i_rotr(e, 11) ^ smpack_i_rotr(e, 25)) + ((e & f) ^ (~e & g))
                      + smpack_i_k[t] + w[t];
        uint32_t t2 = (smpack_i_rotr(a, 2) ^ smpack_i_rotr(a, 13) ^ smpack_i_rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
        k = g; g = f; f = e; e = d + t1; d = c; c = b; b = a; a = t1 + t2;
    }
    h[0] += a; h[1] += b; h[2] += c; h[3] += d; h[4] += e; h[5] += f; h[6] += g; h[7] += k;
}

static void smpack_i_sha_init(smpack_i_sha *s) {
    static const uint32_t h0[8] = {0x6a09e667u, 0xbb67ae85u, 0x3c6ef372u, 0xa54ff53au,
                                   0x510e527fu, 0x9b05688cu, 0x1f83d9abu, 0x5be0cd19u};
    memcpy(s->h, h0, sizeof h0);
    s->fill = 0, s->total = 0;
}

static void smpack_i_sha_update(smpack_i_sha *s, const void *data, size_t n) {
    const unsigned char *p = (const unsigned char *)data;
    s->total += (uint64_t)n;
    if (s->fill) {
        size_t take = 64 - s->fill < n ? 64 - s->fill : n;
        memcpy(s->block + s->fill, p, take);
        s->fill += take; p += take; n -= take;
        if (s->fill < 64) return;
        smpack_i_sha_block(s->h, s->block);
        s->fill = 0;
    }
    for (; n >= 64; p += 64, n -= 64) smpack_i_sha_block(s->h, p);
    if (n) memcpy(s->block, p, n);
    s->fill = n;
}

static void smpack_i_sha_final(smpack_i_sha *s, unsigned char out[32]) {
    uint64_t bits = s->total * 8u;
    unsigned i;
    s->block[s->fill++] = 0x80;
    memset(s->block + s->fill, 0, 64 - s->fill);
    if (s->fill > 56) smpack_i_sha_block(s->h, s->block), memset(s->block, 0, 56);
    for (i = 0; i < 8; i++) s->block[56 + i] = (unsigned char)(bits >> (56 - 8 * i));
    smpack_i_sha_block(s->h, s->block);
    for (i = 0; i < 32; i++) out[i] = (unsigned char)(s->h[i / 4] >> (24 - 8 * (i % 4)));
}

void smpack_sha256(const void *data, size_t size, unsigned char out[32]) {
    smpack_i_sha s;
    smpack_i_sha_init(&s);
    if (data) smpack_i_sha_update(&s, data, size);
    smpack_i_sha_final(&s, out);
}

/* ---- small helpers */

static uint32_t smpack_i_u32(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static uint64_t smpack_i_u64(const unsigned char *p) { return smpack_i_u32(p) | ((uint64_t)smpack_i_u32(p + 4) << 32); }

static const unsigned char *smpack_i_entry(const smpack *pack, uint32_t i) {
    return pack->data + pack->index_at + (size_t)i * SMPACK_ENTRY_SIZE;
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 3, 4)))
#endif
static smpack_status smpack_i_fail(smpack *pack, smpack_status status, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt), vsnprintf(pack->error, sizeof pack->error, fmt, ap), va_end(ap);
    return status;
}

/* The length of a NUL-padded name field; 0 when it is malformed: empty, a NUL before its last non-NUL byte,
   or a byte past ASCII (read_pack refuses the same). */
static size_t smpack_i_name(const unsigned char *field, size_t width) {
    size_t n = width, k;
    while (n && field[n - 1] == 0) n--;
    for (k = 0; k < n; k++)
        if (field[k] == 0 || field[k] > 0x7f) return 0;
    return n;
}

/* Orders entry e against NUL-padded permutation and stage, as Python orders (str, str) tuples of ASCII. */
static int smpack_i_cmp_entry(const unsigned char *e, const unsigned char *perm, const unsigned char *stage) {
    size_t k;
    for (k = 0; k < 24; k++) {
        unsigned a = e[k], b = k < 16 ? perm[k] : stage[k - 16];
        if (a != b) return a < b ? -1 : 1;
        if (a == 0 && k < 16) k = 15; /* the permutations are equal: on to the stage */
        else if (a == 0) return 0;
    }
    return 0;
}

/* A name into dst (width + 1 bytes); for a message (printable), bytes outside printable ASCII as '?'. */
static void smpack_i_copy_name(char *dst, const unsigned char *field, size_t width, int printable) {
    size_t k;
    for (k = 0; k < width && field[k]; k++)
        dst[k] = (char)(printable && (field[k] < 0x20 || field[k] > 0x7e) ? '?' : field[k]);
    dst[k] = 0;
}

/* ---- the metadata: accepted only as exactly the bytes the generator writes, json.dumps(meta, sort_keys=True,
   separators=(",", ":")), so that the key can be hashed from them as they are */

typedef struct smpack_i_json { const unsigned char *m; size_t n, i; const char *why; } smpack_i_json;

static int smpack_i_hex4(const unsigned char *p, uint32_t *v) {
    int k;
    for (*v = 0, k = 0; k < 4; k++) {
        unsigned c = p[k];
        if (c >= '0' && c <= '9') *v = (*v << 4) | (c - '0');
        else if (c >= 'a' && c <= 'f') *v = (*v << 4) | (c - 'a' + 10);
        else return 0; /* upper case too: Python writes lower-case escapes */
    }
    return 1;
}

static int smpack_i_bad(smpack_i_json *j, const char *why) { j->why = why; return 0; }

/* A canonical string at j->i (its opening quote): printable ASCII as itself but `"` and `\`, those and the
   five short escapes as \" \\ \b \f \n \r \t, any other character below 0x20 or from 0x7f as \u with four
   lower-case hex digits. Leaves j->i after the closing quote. */
static int smpack_i_string(smpack_i_json *j) {
    for (j->i++;;) {
        unsigned c;
        uint32_t v;
        if (j->i >= j->n) return smpack_i_bad(j, "a string runs past the end");
        c = j->m[j->i];
        if (c == '"') { j->i++; return 1; }
        if (c < 0x20 || c > 0x7e) return smpack_i_bad(j, "a byte that is not printable ASCII");
        if (c != '\\') { j->i++; continue; }
        c = j->i + 1 < j->n ? j->m[j->i + 1] : 0;
        if (c == '"' || c == '\\' || c == 'b' || c == 'f' || c == 'n' || c == 'r' || c == 't') { j->i += 2; continue; }
        if (c != 'u') return smpack_i_bad(j, "an escape Python does not write");
        if (j->n - j->i < 6 || !smpack_i_hex4(j->m + j->i + 2, &v)) return smpack_i_bad(j, "a malformed \\u escape");
        if ((v >= 0x20 && v < 0x7f) || v == 8 || v == 9 || v == 10 || v == 12 || v == 13)
            return smpack_i_bad(j, "a \\u escape Python writes otherwise");
        j->i += 6;
    }
}

/* The next code point of a canonical string's body at *i, a surrogate pair as one (as Python reads it). */
static uint32_t smpack_i_codepoint(const unsigned char *m, size_t end, size_t *i) {
    uint32_t v, lo;
    unsigned c = m[*i];
    if (c != '\\') { (*i)++; return c; }
    c = m[*i + 1];
    if (c != 'u') {
        *i += 2;
        return c == 'b' ? 8u : c == 'f' ? 12u : c == 'n' ? 10u : c == 'r' ? 13u : c == 't' ? 9u : c;
    }
    smpack_i_hex4(m + *i + 2, &v);
    *i += 6;
    if (v >= 0xd800 && v < 0xdc00 && end - *i >= 6 && m[*i] == '\\' && m[*i + 1] == 'u'
        && smpack_i_hex4(m + *i + 2, &lo) && lo >= 0xdc00 && lo < 0xe000) {
        *i += 6;
        return 0x10000u + ((v - 0xd800u) << 10) + (lo - 0xdc00u);
    }
    return v;
}

/* Keys are sorted by code point (Python's str order), not by their escaped bytes. */
static int smpack_i_key_cmp(const unsigned char *m, size_t a, size_t a_end, size_t b, size_t b_end) {
    while (a < a_end && b < b_end) {
        uint32_t x = smpack_i_codepoint(m, a_end, &a), y = smpack_i_codepoint(m, b_end, &b);
        if (x != y) return x < y ? -1 : 1;
    }
    return (a < a_end) - (b < b_end);
}

/* An integer as Python writes one (no "-0", no leading zero) within 64 bits. No fraction or exponent: a
   float's canonical text is Python's repr, which this reader does not reproduce (read_pack refuses too). */
static int smpack_i_integer(smpack_i_json *j) {
    size_t at = j->i + (j->m[j->i] == '-'), first = at, digits;
    while (at < j->n && j->m[at] >= '0' && j->m[at] <= '9') at++;
    digits = at - first;
    if (!digits || (j->m[first] == '0' && (digits > 1 || first > j->i))) return smpack_i_bad(j, "a malformed number");
    if (at < j->n && (j->m[at] == '.' || j->m[at] == 'e' || j->m[at] == 'E'))
        return smpack_i_bad(j, "a non-integer number");
    if (digits > 19 || (digits == 19 && memcmp(j->m + first, first > j->i ? "9223372036854775808"
                                                                           : "9223372036854775807", 19) > 0))
        return smpack_i_bad(j, "an integer past 64 bits");
    j->i = at;
    return 1;
}

/* One value at j->i; sets *is_smpack when it is the string "smpack". */
static int smpack_i_scalar(smpack_i_json *j, int *is_smpack) {
    const unsigned char *p = j->m + j->i;
    size_t left = j->n - j->i;
    *is_smpack = 0;
    if (*p == '"') {
        if (!smpack_i_string(j)) return 0;
        *is_smpack = j->m + j->i - p == 8 && memcmp(p, "\"smpack\"", 8) == 0;
        return 1;
    }
    if (*p == '-' || (*p >= '0' && *p <= '9')) return smpack_i_integer(j);
    if (left >= 4 && (memcmp(p, "true", 4) == 0 || memcmp(p, "null", 4) == 0)) { j->i += 4; return 1; }
    if (left >= 5 && memcmp(p, "false", 5) == 0) { j->i += 5; return 1; }
    return smpack_i_bad(j, "a byte that starts no JSON value Python writes");
}

static smpack_status smpack_i_meta(smpack *pack, const unsigned char *m, size_t n) {
    /* an explicit stack, not recursion: the depth is bounded whatever the input */
    unsigned char close[SMPACK_META_DEPTH];
    size_t key_at[SMPACK_META_DEPTH], key_end[SMPACK_META_DEPTH];
    int depth = 0, want_key = 0, is_format = 0, format_ok = 0, is_smpack;
    smpack_i_json j;
    j.m = m, j.n = n, j.i = 0, j.why = NULL;
    if (n == 0 || m[0] != '{')
        return smpack_i_fail(pack, SMPACK_ERR_META, "the metadata is not a JSON object (byte %d)", SMPACK_HEADER_SIZE);
    for (;;) {
        if (want_key) { /* a key sorting after the one before, ':', then its value */
            size_t at = j.i + 1, *prev = &key_end[depth - 1];
            if (j.i >= n || m[j.i] != '"') { smpack_i_bad(&j, "an object key that is not a string"); break; }
            if (!smpack_i_string(&j)) break;
            if (*prev && smpack_i_key_cmp(m, key_at[depth - 1], *prev, at, j.i - 1) >= 0) {
                j.i = at - 1, smpack_i_bad(&j, "keys not sorted, or a repeated key"); break;
            }
            key_at[depth - 1] = at, *prev = j.i - 1;
            is_format = depth == 1 && j.i - 1 - at == 6 && memcmp(m + at, "format", 6) == 0;
            if (j.i >= n || m[j.i++] != ':') { smpack_i_bad(&j, "no ':' right after a key"); break; }
            want_key = 0;
            continue;
        }
        if (j.i >= n) { smpack_i_bad(&j, "it ends early"); break; }
        if (m[j.i] == '{' || m[j.i] == '[') { /* a container: empty, or its first key or value next */
            if (depth == SMPACK_META_DEPTH) { smpack_i_bad(&j, "nested deeper than SMPACK_META_DEPTH (32)"); break; }
            close[depth] = m[j.i] == '{' ? '}' : ']', key_end[depth] = 0, is_format = 0;
            want_key = m[j.i++] == '{';
            if (j.i >= n || m[j.i] != close[depth]) { depth++; continue; }
            j.i++, want_key = 0;
        } else if (!smpack_i_scalar(&j, &is_smpack)) {
            break;
        } else {
            format_ok |= is_format && is_smpack, is_format = 0;
        }
        /* after a value: the close of its container(s), the end, or ',' and the next key or value */
        while (depth && j.i < n && m[j.i] == close[depth - 1]) j.i++, depth--;
        if (!depth && j.i != n) { smpack_i_bad(&j, "bytes after the object"); break; }
        if (!depth && !format_ok)
            return smpack_i_fail(pack, SMPACK_ERR_META, "the metadata (%llu bytes at byte %d) is not a shader pack's: no "
                                 "\"format\":\"smpack\"", (unsigned long long)n, SMPACK_HEADER_SIZE);
        if (!depth) return SMPACK_OK;
        if (j.i >= n || m[j.i++] != ',') { smpack_i_bad(&j, "no ',' or close after a value"); break; }
        want_key = close[depth - 1] == '}';
    }
    return smpack_i_fail(pack, SMPACK_ERR_META, "the metadata is not canonical JSON at byte %llu: %s",
                         (unsigned long long)(SMPACK_HEADER_SIZE + j.i), j.why);
}

/* ---- the key: sha256 of ["smpack",1,<meta as in the file>,[["perm","stage","<input key hex>","<sha hex>"],...]] */

static void smpack_i_sha_name(smpack_i_sha *s, const unsigned char *field, size_t width) {
    size_t k, n = smpack_i_name(field, width);
    smpack_i_sha_update(s, "\"", 1);
    for (k = 0; k < n; k++) { /* ASCII without NUL, escaped as json.dumps escapes it */
        static const char hex[] = "0123456789abcdef";
        unsigned c = field[k];
        char e[6] = {'\\', 'u', '0', '0', 0, 0};
        const char *short_escape = c == '"' ? "\"" : c == '\\' ? "\\" : c == 8 ? "b" : c == 12 ? "f" : c == 10 ? "n"
                                 : c == 13 ? "r" : c == 9 ? "t" : NULL;
        if (short_escape) { e[1] = *short_escape; smpack_i_sha_update(s, e, 2); }
        else if (c < 0x20 || c == 0x7f) { e[4] = hex[c >> 4]; e[5] = hex[c & 15]; smpack_i_sha_update(s, e, 6); }
        else { e[0] = (char)c; smpack_i_sha_update(s, e, 1); }
    }
    smpack_i_sha_update(s, "\",", 2);
}

static void smpack_i_sha_hex(smpack_i_sha *s, const unsigned char *raw, char after) {
    static const char digits[] = "0123456789abcdef";
    char hex[67];
    int k;
    for (hex[0] = hex[65] = '"', hex[66] = after, k = 0; k < 32; k++)
        hex[1 + 2 * k] = digits[raw[k] >> 4], hex[2 + 2 * k] = digits[raw[k] & 15];
    smpack_i_sha_update(s, hex, 67);
}

/* The key the pack's metadata and index give (whatever its header says). */
static void smpack_i_key(const smpack *pack, unsigned char out[32]) {
    smpack_i_sha s;
    uint32_t i;
    smpack_i_sha_init(&s);
    smpack_i_sha_update(&s, "[\"smpack\",1,", 12);
    smpack_i_sha_update(&s, pack->data + SMPACK_HEADER_SIZE, pack->meta_length);
    smpack_i_sha_update(&s, ",[", 2);
    for (i = 0; i < pack->count; i++) {
        const unsigned char *e = smpack_i_entry(pack, i);
        smpack_i_sha_update(&s, i ? ",[" : "[", i ? 2u : 1u);
        smpack_i_sha_name(&s, e, 16);
        smpack_i_sha_name(&s, e + 16, 8);
        smpack_i_sha_hex(&s, e + 24, ',');
        smpack_i_sha_hex(&s, e + 56, ']');
    }
    smpack_i_sha_update(&s, "]]", 2);
    smpack_i_sha_final(&s, out);
}

/* ---- the index and the blobs, entry by entry in read_pack's order */

static smpack_status smpack_i_trailing(smpack *pack, uint64_t end) {
    if (end == (uint64_t)pack->size) return SMPACK_OK;
    return smpack_i_fail(pack, SMPACK_ERR_OVERLAP, "%llu bytes of trailing garbage after the last blob (byte %llu)",
                         (unsigned long long)((uint64_t)pack->size - end), (unsigned long long)end);
}

/* read_pack's walk over the distinct offsets in ascending order, each blob's end the next one's start; only
   for blobs not laid out in order of first use (as the generator lays them out): O(blobs x entries). */
static smpack_status smpack_i_contiguous(smpack *pack) {
    uint64_t cur = pack->blobs_at, prev = 0;
    int first = 1;
    for (;;) {
        uint64_t best = 0, best_len = 0;
        int found = 0;
        uint32_t i;
        for (i = 0; i < pack->count; i++) {
            uint64_t o = smpack_i_u64(smpack_i_entry(pack, i) + 88);
            if ((first || o > prev) && (!found || o < best)) {
                best = o; best_len = smpack_i_u64(smpack_i_entry(pack, i) + 96); found = 1;
            }
        }
        if (!found) return smpack_i_trailing(pack, cur);
        if (best != cur)
            return smpack_i_fail(pack, SMPACK_ERR_OVERLAP, "the blobs are not contiguous: a gap or an overlap at byte %llu",
                                 (unsigned long long)(best < cur ? best : cur));
        cur = best + best_len, prev = best, first = 0;
    }
}

static smpack_status smpack_i_entries(smpack *pack) {
    uint64_t size = (uint64_t)pack->size, end = (uint64_t)pack->blobs_at;
    int in_order = 1, zero_at_end = 0; /* so far the distinct blobs cover blobs_at..end, in order of first use */
    uint32_t i;
    for (i = 0; i < pack->count; i++) {
        const unsigned char *e = smpack_i_entry(pack, i), *same = NULL;
        uint64_t offset = smpack_i_u64(e + 88), length = smpack_i_u64(e + 96);
        unsigned long long at = (unsigned long long)(e - pack->data);
        char perm[17], stage[9];
        unsigned char got[32];
        if (!smpack_i_name(e, 16) || !smpack_i_name(e + 16, 8))
            return smpack_i_fail(pack, SMPACK_ERR_INDEX, "index entry %lu (byte %llu) has a malformed %s field: not "
                                 "NUL-padded ASCII", (unsigned long)i, at + (smpack_i_name(e, 16) ? 16 : 0),
                                 smpack_i_name(e, 16) ? "stage" : "permutation");
        smpack_i_copy_name(perm, e, 16, 1);
        smpack_i_copy_name(stage, e + 16, 8, 1);
        if (i && smpack_i_cmp_entry(e, e - SMPACK_ENTRY_SIZE, e - SMPACK_ENTRY_SIZE + 16) <= 0)
            return smpack_i_fail(pack, SMPACK_ERR_ORDER, "index entry %lu (%s %s, byte %llu) is out of order or repeated",
                                 (unsigned long)i, perm, stage, at);
        if (offset < (uint64_t)pack->blobs_at || offset > size || length > size - offset) /* offset + length may wrap */
            return smpack_i_fail(pack, SMPACK_ERR_BOUNDS, "index entry %lu (%s %s) points at %llu bytes from byte %llu, "
                                 "outside the blobs (%llu..%llu)", (unsigned long)i, perm, stage,
                                 (unsigned long long)length, (unsigned long long)offset,
                                 (unsigned long long)pack->blobs_at, (unsigned long long)size);
        if (!(in_order && offset == end && !zero_at_end)) { /* an earlier entry's blob? the latest at this offset */
            const unsigned char *p = e;
            while (!same && p != smpack_i_entry(pack, 0))
                if (smpack_i_u64((p -= SMPACK_ENTRY_SIZE) + 88) == offset) same = p;
        }
        if (same && smpack_i_u64(same + 96) == length) { /* its bytes hashed already: compare the recorded hashes */
            if (memcmp(same + 56, e + 56, 32) == 0) continue;
            memcpy(got, same + 56, 32); /* the bytes' hash: `same` passed */
        } else {
            smpack_sha256(pack->data + (size_t)offset, (size_t)length, got);
        }
        if (memcmp(got, e + 56, 32) != 0)
            return smpack_i_fail(pack, SMPACK_ERR_HASH, "sha256 mismatch in the blob of %s %s (%llu bytes from byte %llu)",
                                 perm, stage, (unsigned long long)length, (unsigned long long)offset);
        if (same) /* read_pack hashes before it compares the lengths */
            return smpack_i_fail(pack, SMPACK_ERR_OVERLAP, "index entry %lu (%s %s) overlaps another blob at byte %llu",
                                 (unsigned long)i, perm, stage, (unsigned long long)offset);
        if (in_order && offset == end && !zero_at_end) { end += length; zero_at_end = length == 0; }
        else in_order = 0;
    }
    return in_order ? smpack_i_trailing(pack, end) : smpack_i_contiguous(pack);
}

/* ---- opening */

static smpack_status smpack_i_open(smpack *pack) {
    const unsigned char *d = pack->data;
    uint64_t meta_length, index_at, blobs_at;
    uint32_t reserved;
    unsigned char key[32];
    smpack_status st;
    size_t k;
    if (pack->size < 8 || memcmp(d, "SMPACK\r\n", 8) != 0)
        return smpack_i_fail(pack, SMPACK_ERR_MAGIC, "bad magic at byte 0 (expected \"SMPACK\\r\\n\")%s",
                             pack->size < 8 ? ": the file is shorter than it" : "");
    if (pack->size < SMPACK_HEADER_SIZE)
        return smpack_i_fail(pack, SMPACK_ERR_TRUNCATED, "truncated: %llu bytes, shorter than the %d-byte header",
                             (unsigned long long)pack->size, SMPACK_HEADER_SIZE);
    pack->version = smpack_i_u32(d + 8);
    pack->count = smpack_i_u32(d + 12);
    memcpy(pack->key, d + 16, 32);
    meta_length = smpack_i_u32(d + 48);
    reserved = smpack_i_u32(d + 52);
    if (pack->version != SMPACK_FORMAT_VERSION)
        return smpack_i_fail(pack, SMPACK_ERR_VERSION, "format version %lu (byte 8), this reader reads version %d",
                             (unsigned long)pack->version, SMPACK_FORMAT_VERSION);
    if (reserved != 0)
        return smpack_i_fail(pack, SMPACK_ERR_HEADER, "reserved header field (byte 52) is %lu, not 0", (unsigned long)reserved);
    /* in 64 bits, whatever size_t is: a u32 length and a u32 count times 104 cannot wrap them */
    index_at = (SMPACK_HEADER_SIZE + meta_length + 7u) / 8u * 8u;
    blobs_at = index_at + (uint64_t)pack->count * SMPACK_ENTRY_SIZE;
    if (blobs_at > (uint64_t)pack->size)
        return smpack_i_fail(pack, SMPACK_ERR_TRUNCATED, "truncated: the header announces %lu entries and %llu bytes of "
                             "metadata, ending at byte %llu, but the file has %llu bytes", (unsigned long)pack->count,
                             (unsigned long long)meta_length, (unsigned long long)blobs_at,
                             (unsigned long long)pack->size);
    pack->meta_length = (size_t)meta_length;
    pack->index_at = (size_t)index_at;
    pack->blobs_at = (size_t)blobs_at;
    if ((st = smpack_i_meta(pack, d + SMPACK_HEADER_SIZE, pack->meta_length)) != SMPACK_OK) return st;
    for (k = SMPACK_HEADER_SIZE + pack->meta_length; k < pack->index_at; k++)
        if (d[k]) return smpack_i_fail(pack, SMPACK_ERR_META, "non-zero padding after the metadata (byte %llu)",
                                       (unsigned long long)k);
    if ((st = smpack_i_entries(pack)) != SMPACK_OK) return st;
    smpack_i_key(pack, key);
    if (memcmp(key, pack->key, 32) != 0)
        return smpack_i_fail(pack, SMPACK_ERR_KEY, "the pack key (byte 16) does not match its metadata and index");
    return SMPACK_OK;
}

smpack_status smpack_open_memory(smpack *pack, const void *data, size_t size) {
    smpack_status st;
    if (!pack) return SMPACK_ERR_ARGUMENT;
    memset(pack, 0, sizeof *pack);
    if (!data) return smpack_i_fail(pack, SMPACK_ERR_ARGUMENT, "smpack_open_memory: data is NULL");
    pack->data = (const unsigned char *)data;
    pack->size = size;
    if ((st = smpack_i_open(pack)) != SMPACK_OK) { /* a refused pack keeps its message, nothing else */
        char why[sizeof pack->error];
        memcpy(why, pack->error, sizeof why);
        memset(pack, 0, sizeof *pack);
        memcpy(pack->error, why, sizeof why);
    }
    return st;
}

smpack_status smpack_open_file(smpack *pack, const char *path) {
    FILE *f;
    unsigned char *buf;
    size_t cap = 65536, len = 0, got = 1;
    long hint;
    smpack_status st;
    if (!pack) return SMPACK_ERR_ARGUMENT;
    memset(pack, 0, sizeof *pack);
    if (!path) return smpack_i_fail(pack, SMPACK_ERR_ARGUMENT, "smpack_open_file: path is NULL");
    errno = 0;
    if (!(f = fopen(path, "rb")))
        return smpack_i_fail(pack, SMPACK_ERR_IO, "cannot open the shader pack: %s", errno ? strerror(errno) : "fopen failed");
    /* the size is a first guess only (a directory's or a device's may be anything): reading decides */
    if (fseek(f, 0, SEEK_END) == 0 && (hint = ftell(f)) >= 0 && (unsigned long)hint < (1ul << 30)) cap = (size_t)hint + 1;
    rewind(f);
    buf = (unsigned char *)malloc(cap);
    while (buf && got) {
        if (len == cap) {
            unsigned char *more = cap > (size_t)-1 / 2 ? NULL : (unsigned char *)realloc(buf, cap * 2);
            if (!more) free(buf);
            buf = more;
            cap *= 2;
            if (!buf) break;
        }
        errno = 0;
        len += got = fread(buf + len, 1, cap - len, f);
    }
    if (!buf || ferror(f)) {
        int e = errno;
        st = buf ? smpack_i_fail(pack, SMPACK_ERR_IO, "cannot read the shader pack: %s", e ? strerror(e) : "read error")
                 : smpack_i_fail(pack, SMPACK_ERR_NOMEM, "out of memory after reading %llu bytes", (unsigned long long)len);
        free(buf);
        fclose(f);
        return st;
    }
    fclose(f);
    if ((st = smpack_open_memory(pack, buf, len)) != SMPACK_OK) free(buf);
    else pack->owned = buf;
    return st;
}

void smpack_close(smpack *pack) {
    if (!pack) return;
    free(pack->owned);
    memset(pack, 0, sizeof *pack);
}

/* ---- reading an open pack */

const char *smpack_error(const smpack *pack) { return pack ? pack->error : "no pack (NULL)"; }

const char *smpack_status_name(smpack_status s) {
    static const char *const names[] = {
        "SMPACK_OK", "SMPACK_ERR_ARGUMENT", "SMPACK_ERR_IO", "SMPACK_ERR_NOMEM", "SMPACK_ERR_TRUNCATED",
        "SMPACK_ERR_MAGIC", "SMPACK_ERR_VERSION", "SMPACK_ERR_HEADER", "SMPACK_ERR_META", "SMPACK_ERR_INDEX",
        "SMPACK_ERR_ORDER", "SMPACK_ERR_BOUNDS", "SMPACK_ERR_OVERLAP", "SMPACK_ERR_HASH", "SMPACK_ERR_KEY",
        "SMPACK_ERR_NOT_FOUND"};
    return (unsigned)s < sizeof names / sizeof names[0] ? names[s] : "SMPACK_ERR_UNKNOWN";
}

uint32_t smpack_count(const smpack *pack) { return pack && pack->data ? pack->count : 0; }

smpack_status smpack_entry_at(const smpack *pack, uint32_t i, smpack_entry *out) {
    const unsigned char *e;
    if (!out || i >= smpack_count(pack)) return SMPACK_ERR_ARGUMENT;
    e = smpack_i_entry(pack, i);
    smpack_i_copy_name(out->permutation, e, 16, 0);
    smpack_i_copy_name(out->stage, e + 16, 8, 0);
    memcpy(out->input_key, e + 24, 32);
    memcpy(out->sha256, e + 56, 32);
    out->offset = smpack_i_u64(e + 88);
    out->length = smpack_i_u64(e + 96);
    out->data = pack->data + (size_t)out->offset;
    return SMPACK_OK;
}

smpack_status smpack_find(const smpack *pack, const char *permutation, const char *stage, smpack_entry *out) {
    unsigned char perm[16], stg[8];
    uint32_t lo = 0, hi = smpack_count(pack);
    size_t k;
    if (!pack || !permutation || !stage || !out) return SMPACK_ERR_ARGUMENT;
    for (k = 0; k < 16 && permutation[k]; k++) perm[k] = (unsigned char)permutation[k];
    if (permutation[k]) return SMPACK_ERR_ARGUMENT; /* longer than its field */
    memset(perm + k, 0, 16 - k);
    for (k = 0; k < 8 && stage[k]; k++) stg[k] = (unsigned char)stage[k];
    if (stage[k]) return SMPACK_ERR_ARGUMENT;
    memset(stg + k, 0, 8 - k);
    while (lo < hi) { /* the index is sorted: open checked it */
        uint32_t mid = lo + (hi - lo) / 2;
        int c = smpack_i_cmp_entry(smpack_i_entry(pack, mid), perm, stg);
        if (c == 0) return smpack_entry_at(pack, mid, out);
        if (c < 0) lo = mid + 1;
        else hi = mid;
    }
    return SMPACK_ERR_NOT_FOUND;
}

const char *smpack_meta(const smpack *pack, size_t *length) {
    int open = pack && pack->data;
    if (length) *length = open ? pack->meta_length : 0;
    return open ? (const char *)pack->data + SMPACK_HEADER_SIZE : NULL;
}

#ifdef __cplusplus
}
#endif
#endif /* SHADERMATRIX_PACK_IMPLEMENTATION */
