/* The one translation unit that compiles pack.h's implementation (a single-header library: every other file
 * includes only its declarations). */
#define SHADERMATRIX_PACK_IMPLEMENTATION
#include <shadermatrix/pack.h>
