/* The pack reader's test driver (tests/native/test_pack_h.py builds it under AddressSanitizer and
   UndefinedBehaviorSanitizer). Every pack it opens lies in a malloc'd buffer of exactly its size, so a read
   one byte past the end is a sanitizer report, not a silent success.

     pack_check FILE        smpack_open_file; prints the verdict, and for a pack that opens its key and entries
     pack_check -           the same for the bytes on stdin, through smpack_open_memory
     pack_check --batch     stdin: records of (u64 little-endian length, bytes); one verdict line per record
     pack_check --sha256    stdin: records as for --batch; prints smpack_sha256 of each in hex, one a line

   A verdict line is "<status name>\t<message>", the message's bytes outside printable ASCII as \xNN. For a pack that opens: "key <hex> meta <length>", then
   one line per entry in index order: "<permutation> <stage> <input key hex> <sha256 hex> <offset> <length>".
   Exit status 0 whatever the verdict; 3 when the reader contradicts itself (smpack_find, smpack_entry_at
   or a blob's hash disagreeing with what open accepted). */
#define SHADERMATRIX_PACK_IMPLEMENTATION
#include "shadermatrix/pack.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void hex(const unsigned char *raw, size_t n) {
    size_t k;
    for (k = 0; k < n; k++) printf("%02x", raw[k]);
}

static unsigned char *slurp(FILE *f, size_t *size) {
    size_t cap = 1 << 16, len = 0, got;
    unsigned char *buf = (unsigned char *)malloc(cap), *exact;
    while (buf && (got = fread(buf + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) buf = (unsigned char *)realloc(buf, cap *= 2);
    }
    if (!buf) return NULL;
    exact = (unsigned char *)malloc(len ? len : 1); /* exactly the bytes: nothing after them to read by mistake */
    if (exact && len) memcpy(exact, buf, len);
    free(buf);
    *size = len;
    return exact;
}

/* Everything a caller can ask of an open pack, checked against itself. */
static int consistent(const smpack *pack) {
    uint32_t i, n = smpack_count(pack);
    smpack_entry e, f;
    size_t meta_len;
    unsigned char sha[32];
    if (!smpack_meta(pack, &meta_len)) return 0;
    for (i = 0; i < n; i++) {
        if (smpack_entry_at(pack, i, &e) != SMPACK_OK) return 0;
        if (smpack_find(pack, e.permutation, e.stage, &f) != SMPACK_OK || f.offset != e.offset || f.data != e.data)
            return 0;
        smpack_sha256(e.data, (size_t)e.length, sha);
        if (memcmp(sha, e.sha256, 32) != 0) return 0;
    }
    if (smpack_entry_at(pack, n, &e) != SMPACK_ERR_ARGUMENT) return 0;
    if (smpack_find(pack, "no such permutation", "frag", &e) != SMPACK_ERR_ARGUMENT) return 0;
    if (smpack_find(pack, "~", "~", &e) != SMPACK_ERR_NOT_FOUND) return 0;
    return 1;
}

static int report(smpack_status st, smpack *pack, int entries) {
    uint32_t i;
    smpack_entry e;
    size_t meta_len = 0;
    const char *m;
    printf("%s\t", smpack_status_name(st));
    for (m = smpack_error(pack); *m; m++)
        if (*m >= 0x20 && *m < 0x7f && *m != '\\') putchar(*m);
        else printf("\\x%02x", (unsigned)(unsigned char)*m);
    putchar('\n');
    if (st != SMPACK_OK) return smpack_count(pack) == 0 && smpack_meta(pack, NULL) == NULL ? 0 : 3;
    if (!consistent(pack)) {
        printf("INCONSISTENT\n");
        return 3;
    }
    if (entries) {
        smpack_meta(pack, &meta_len);
        printf("key ");
        hex(pack->key, 32);
        printf(" meta %lu\n", (unsigned long)meta_len);
        for (i = 0; i < smpack_count(pack); i++) {
            smpack_entry_at(pack, i, &e);
            printf("%s %s ", e.permutation, e.stage);
            hex(e.input_key, 32);
            printf(" ");
            hex(e.sha256, 32);
            printf(" %llu %llu\n", (unsigned long long)e.offset, (unsigned long long)e.length);
        }
    }
    return 0;
}

static int batch(int sha_only) {
    unsigned char head[8];
    int rc = 0;
    while (fread(head, 1, 8, stdin) == 8) {
        size_t size = 0, k;
        unsigned char *data;
        smpack pack;
        for (k = 0; k < 8; k++) size |= (size_t)head[k] << (8 * k);
        data = (unsigned char *)malloc(size ? size : 1);
        if (!data || fread(data, 1, size, stdin) != size) return 2;
        if (sha_only) {
            unsigned char sha[32];
            smpack_sha256(data, size, sha);
            hex(sha, 32);
            printf("\n");
        } else {
            rc |= report(smpack_open_memory(&pack, data, size), &pack, 0);
            smpack_close(&pack);
        }
        free(data);
    }
    fflush(stdout);
    return rc;
}

int main(int argc, char **argv) {
    smpack pack;
    smpack_status st;
    int rc;
    if (argc != 2) {
        fprintf(stderr, "usage: pack_check FILE | - | --batch | --sha256\n");
        return 2;
    }
    if (strcmp(argv[1], "--batch") == 0 || strcmp(argv[1], "--sha256") == 0) return batch(argv[1][2] == 's');
    if (strcmp(argv[1], "-") == 0) {
        size_t size = 0;
        unsigned char *data = slurp(stdin, &size);
        if (!data) return 2;
        st = smpack_open_memory(&pack, data, size);
        rc = report(st, &pack, 1);
        smpack_close(&pack);
        free(data);
        return rc;
    }
    st = smpack_open_file(&pack, argv[1]);
    rc = report(st, &pack, 1);
    smpack_close(&pack);
    return rc;
}
