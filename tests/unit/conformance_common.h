/* Shared by the conformance-vector generator and its test: the integer grid point of a valid
 * code, as the spec defines it (grid methods and OSS: q1..qK; Any: x2..xK). */
#ifndef SKINPACK_CONFORMANCE_COMMON_H
#define SKINPACK_CONFORMANCE_COMMON_H

#include "../../native/src/codec_internal.h"

/* Returns the number of grid values written (K, or K - 1 for Any; 0 for K = 1). */
static inline uint32_t conformance_grid(const sp_codec* codec, uint64_t code, uint64_t* grid)
{
    uint32_t k = codec->influences;
    if (k == 1) return 0;
    if (codec->method == SP_METHOD_ANY) {
        for (uint32_t a = 0; a + 1 < k; ++a) {
            grid[a] = code % codec->axis_samples[a];
            code /= codec->axis_samples[a];
        }
        return k - 1;
    }
    if (codec->method == SP_METHOD_OSS) sp_oss_unpack(codec->n, k, code, grid);
    else sp_grid_unpack(codec, code, grid);
    return k;
}

#endif
