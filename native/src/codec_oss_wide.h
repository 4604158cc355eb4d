/*
 * The OSS batch paths for codes past the double lanes' exact range (internal): K = 3 past
 * N = 2^24, K = 4 past N = 3 * 2^15, K = 2 past N = 2^48 (every width up to 64 bits; K = 2 encode
 * past N = 2^49 in sp_grid_round_pair's exact rounding, with FMA residuals). The driver is
 * codec_oss_wide_simd.h, the per-ISA files codec_oss_batch_avx2.c and codec_oss_batch_avx512.c;
 * codec_oss_batch.c dispatches. Also the limits of every lane kind, which the drivers, the
 * dispatch and the tests share.
 */
#ifndef SKINPACK_CODEC_OSS_WIDE_H
#define SKINPACK_CODEC_OSS_WIDE_H

#include "codec_internal.h"

/* Largest N per K for which the double lanes are exact (codec_oss_simd.h): every value with a
 * fractional quarter or half (row and layer numerators, the row root's argument) below 2^51,
 * every integer (the layer root's argument 8(N+1)^3 + ...) below 2^53, codes below 2^52 (AVX2's
 * conversion), and the layer numerator 9 u(k) + 12 below 2^50.3 for its floor by multiplication.
 * K = 3: rows s_N(j) < N^2/3 + N, apex^2 = (2N + 1)^2 < 2^50 at N = 2^24.
 * K = 4: 8(N + 1)^3 < 2^52.8 and 9 u(k) < 2^48.8 at N = 3 * 2^15 (codes of up to 45 bits). */
#define BATCH_MAX_N2 ((uint64_t)1 << 48)
#define BATCH_MAX_N3 ((uint64_t)1 << 24)
#define BATCH_MAX_N4 ((uint64_t)3 << 15)

/* Within the double lanes, the decode ranges that run in 32-bit lanes (codec_oss_simd.h): the
 * narrow codes, whose every exact intermediate is an int32, and K = 4 with the in-layer index in
 * int32 (the split). */
#define NARROW_MAX_N3 8192  /* apex^2 and 12 w < 2^28.1; codes < 2^24.5 */
#define NARROW_MAX_N4 1024  /* 9 u((N + 1) / 2) < 2^29.1, 8 (N + 1)^3 < 2^33.1 (float); codes < 2^26 */
#define SPLIT_MAX_N4 80264  /* the largest N with (N^2 + N + 1) / 3 <= 2^31 - 1 */

/* Which lanes a codec takes: none, the double lanes, or the wide ones (past the double lanes'
 * N, every N of a 64-bit code: K = 3 grid coordinates below 2^35, K = 4 layers below 2^23, whose
 * in-layer indices stay below 2^47 in double). The same lanes both ways (K = 2 encode past 2^49:
 * the exact pair rounding). codec_oss_batch.c dispatches by it; the tests that compile a driver
 * themselves pick theirs by it. */
typedef enum { SP_LANES_NONE, SP_LANES_DOUBLE, SP_LANES_WIDE } sp_oss_lanes;

SP_INLINE sp_oss_lanes sp_oss_lanes_for(const sp_codec* codec)
{
    uint32_t k = codec->influences;
    if (codec->method != SP_METHOD_OSS || k < 2 || k > 4 || codec->n < 2) return SP_LANES_NONE;
    uint64_t limit = k == 2 ? BATCH_MAX_N2 : (k == 3 ? BATCH_MAX_N3 : BATCH_MAX_N4);
    return codec->n <= limit ? SP_LANES_DOUBLE : SP_LANES_WIDE;
}

/* Encode `count` vertices of k weights (significant may be NULL) or decode `count` codes, whole
 * blocks only (8 lanes for AVX-512, 4 for AVX2), bit-identical to sp_oss_encode_one and
 * sp_oss_decode_one; return how many leading vertices were done. Decode stops before a block
 * holding a code above max_code; with stream set, and weights aligned as the ISA's streaming
 * stores need, it stores them by those and fences them (codec_oss_simd.h's prefetch_decode).
 * Call only where sp_cpu_isa() has the ISA and
 * sp_oss_lanes_for allows it. The types are those of every per-ISA path
 * (codec_internal.h's sp_oss_encode_avx2 ... too), and of the dispatch's pointers. */
typedef size_t sp_oss_encode_path(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                  uint8_t* significant);
typedef size_t sp_oss_decode_path(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                                  int stream);
sp_oss_encode_path sp_oss_wide_encode_avx2, sp_oss_wide_encode_avx512;
sp_oss_decode_path sp_oss_wide_decode_avx2, sp_oss_wide_decode_avx512;

#endif
