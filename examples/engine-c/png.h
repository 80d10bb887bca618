/* A PNG writer for the frame: 8-bit RGBA, no interlace, filter 0 on every row, the zlib stream made of
 * stored (uncompressed) deflate blocks. PNG only requires a valid zlib stream, not a compressed one, so no
 * zlib library is needed: what this writes is what `shadermatrix render` writes, pixel for pixel (a
 * larger file; the comparison reads pixels, not bytes). */
#ifndef ENGINE_PNG_H
#define ENGINE_PNG_H

#include <stdbool.h>
#include <stdint.h>

/* `rgba`: height rows of width × 4 bytes, row 0 the top of the image. Written atomically. */
bool png_write_rgba(const char *path, const unsigned char *rgba, uint32_t width, uint32_t height);

#endif
