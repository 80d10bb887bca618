/* libFuzzer harness of include/shadermatrix/pack.h, built with clang-14 -fsanitize=fuzzer,address,undefined
   (tests/native/test_pack_h_fuzz.py runs it, bounded, under the slow marker).

   Each input is opened three times: as it is; with its blobs' sha256 and its pack key made right wherever
   its header allows, so that the mutations reach the checks after the hashes (contiguity, overlaps, the
   order, the names) instead of stopping at a hash mismatch; and as the metadata of a pack without entries
   (header, padding and key made right), so that they reach every path of the canonical-JSON check. An input that opens is then read through every
   function; a refusal must say why. libFuzzer hands over exactly `size` bytes, and the fixed copy is a
   buffer of exactly `size` bytes too: a read past either is AddressSanitizer's report. */
#define SHADERMATRIX_PACK_IMPLEMENTATION
#include "shadermatrix/pack.h"

#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void read_all(const smpack *pack) {
    volatile unsigned sink = 0;
    size_t n = 0, k;
    const char *meta = smpack_meta(pack, &n);
    uint32_t i;
    smpack_entry e, f;
    for (k = 0; k < n; k++) sink += (unsigned char)meta[k];
    for (i = 0; i < smpack_count(pack); i++) {
        if (smpack_entry_at(pack, i, &e) != SMPACK_OK) abort();
        if (smpack_find(pack, e.permutation, e.stage, &f) != SMPACK_OK || f.data != e.data) abort();
        if (e.length) sink += e.data[0] + e.data[e.length - 1];
    }
    (void)sink;
}

/* The hashes, then the key, recomputed in place (the header's own internals: this file includes them). */
static void make_hashes_right(unsigned char *d, size_t size) {
    smpack p;
    uint64_t index_at, blobs_at;
    uint32_t i;
    if (size < SMPACK_HEADER_SIZE) return;
    memset(&p, 0, sizeof p);
    p.data = d, p.size = size, p.count = smpack_i_u32(d + 12), p.meta_length = smpack_i_u32(d + 48);
    index_at = (SMPACK_HEADER_SIZE + (uint64_t)p.meta_length + 7u) / 8u * 8u;
    blobs_at = index_at + (uint64_t)p.count * SMPACK_ENTRY_SIZE;
    if (blobs_at > size) return;
    p.index_at = (size_t)index_at, p.blobs_at = (size_t)blobs_at;
    for (i = 0; i < p.count; i++) {
        unsigned char *e = d + p.index_at + (size_t)i * SMPACK_ENTRY_SIZE;
        uint64_t offset = smpack_i_u64(e + 88), length = smpack_i_u64(e + 96);
        if (offset >= blobs_at && offset <= size && length <= size - offset)
            smpack_sha256(d + (size_t)offset, (size_t)length, e + 56);
    }
    smpack_i_key(&p, d + 16);
}

static void open_and_read(const unsigned char *data, size_t size) {
    smpack pack;
    if (smpack_open_memory(&pack, data, size) == SMPACK_OK) read_all(&pack);
    else if (smpack_error(&pack)[0] == 0 || smpack_count(&pack) != 0) abort();
    smpack_close(&pack);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    size_t padded = (SMPACK_HEADER_SIZE + size + 7) / 8 * 8;
    unsigned char *fixed = (unsigned char *)malloc(size ? size : 1), *as_meta = (unsigned char *)calloc(padded, 1);
    open_and_read(data, size);
    if (fixed && as_meta && size < 0xffffffffu) {
        if (size) memcpy(fixed, data, size);
        make_hashes_right(fixed, size);
        open_and_read(fixed, size);
        memcpy(as_meta, "SMPACK\r\n\1\0\0\0", 12);
        as_meta[48] = (unsigned char)size, as_meta[49] = (unsigned char)(size >> 8);
        as_meta[50] = (unsigned char)(size >> 16), as_meta[51] = (unsigned char)(size >> 24);
        if (size) memcpy(as_meta + SMPACK_HEADER_SIZE, data, size);
        make_hashes_right(as_meta, padded);
        open_and_read(as_meta, padded);
    }
    free(fixed);
    free(as_meta);
    return 0;
}
