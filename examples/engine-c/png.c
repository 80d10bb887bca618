/* See png.h. References: PNG (Third Edition) §5 datastream and §11 IHDR/IDAT/IEND; RFC 1950 (zlib: header,
 * Adler-32 trailer) and RFC 1951 §3.2.4 (a stored block: BFINAL/BTYPE=00 byte, LEN, NLEN, the bytes). */
#include "png.h"

#include <stdlib.h>
#include <string.h>

#include "util.h"

static uint32_t crc_table[256];

static void make_crc_table(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++)
            c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc32_update(uint32_t crc, const unsigned char *p, size_t n)
{
    for (size_t i = 0; i < n; i++)
        crc = crc_table[(crc ^ p[i]) & 0xFF] ^ (crc >> 8);
    return crc;
}

static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* Appends one chunk (length, type, data, CRC over type and data) at out + *at. */
static void chunk(unsigned char *out, size_t *at, const char type[4], const unsigned char *data, uint32_t n)
{
    unsigned char *p = out + *at;
    put32(p, n);
    memcpy(p + 4, type, 4);
    if (n)
        memcpy(p + 8, data, n);
    put32(p + 8 + n, crc32_update(0xFFFFFFFFu, p + 4, 4 + (size_t)n) ^ 0xFFFFFFFFu);
    *at += 12 + (size_t)n;
}

bool png_write_rgba(const char *path, const unsigned char *rgba, uint32_t width, uint32_t height)
{
    make_crc_table();
    size_t row = 1 + 4 * (size_t)width, raw_size = row * height;
    size_t blocks = raw_size / 65535 + 1;  /* a stored block holds at most 65535 bytes; the last may be empty */
    size_t z_size = 2 + raw_size + 5 * blocks + 4;
    if (z_size > 0x7FFFFFFFu)
        return fail("%s: a %u x %u image does not fit one PNG chunk", path, width, height);
    unsigned char *raw = malloc(raw_size), *z = malloc(z_size), *file = malloc(z_size + 8 + 25 + 12 + 12);
    bool ok = raw && z && file;
    if (!ok) {
        fail("%s: out of memory", path);
        goto done;
    }
    for (uint32_t y = 0; y < height; y++) {  /* filter type 0 (None) on every row */
        raw[y * row] = 0;
        memcpy(raw + y * row + 1, rgba + (size_t)y * 4 * width, 4 * (size_t)width);
    }
    size_t at = 0;
    z[at++] = 0x78;  /* CMF: deflate, 32 KiB window */
    z[at++] = 0x01;  /* FLG: no dictionary, fastest; (0x78 << 8 | 0x01) % 31 == 0 */
    uint32_t a = 1, b = 0;  /* Adler-32 of the uncompressed bytes */
    for (size_t i = 0; i < raw_size; i++) {
        a = (a + raw[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    for (size_t k = 0, left = raw_size; k < blocks; k++) {
        uint32_t n = left > 65535 ? 65535 : (uint32_t)left;
        z[at++] = k + 1 == blocks ? 1 : 0;  /* BFINAL on the last, BTYPE 00 (stored) */
        z[at++] = (unsigned char)n;
        z[at++] = (unsigned char)(n >> 8);
        z[at++] = (unsigned char)~n;
        z[at++] = (unsigned char)(~n >> 8);
        memcpy(z + at, raw + (raw_size - left), n);
        at += n;
        left -= n;
    }
    put32(z + at, b << 16 | a);
    at += 4;
    static const unsigned char SIGNATURE[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    unsigned char ihdr[13];
    put32(ihdr, width);
    put32(ihdr + 4, height);
    ihdr[8] = 8;   /* bit depth */
    ihdr[9] = 6;   /* colour type: RGBA */
    ihdr[10] = 0;  /* compression: deflate */
    ihdr[11] = 0;  /* filter method 0 */
    ihdr[12] = 0;  /* no interlace */
    size_t n = 0;
    memcpy(file, SIGNATURE, 8);
    n = 8;
    chunk(file, &n, "IHDR", ihdr, 13);
    chunk(file, &n, "IDAT", z, (uint32_t)at);
    chunk(file, &n, "IEND", NULL, 0);
    ok = write_file_atomic(path, file, n);
done:
    free(raw);
    free(z);
    free(file);
    return ok;
}
