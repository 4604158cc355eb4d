/*
 * The OSS batch paths for codes past the double lanes' exact range (internal): K = 3 past
 * N = 2^24, K = 4 past N = 3 * 2^15, K = 2 past N = 2^48 (every width up to 64 bits; K = 2 encode
 * past N = 2^49 in sp_grid_round_pair's exact rounding, with FMA residuals). The driver is
 * codec_oss_wide_simd.h, the per-ISA files codec_oss_batch_avx2.c and codec_oss_batch_avx512.c;
 * codec_oss_batch.c dispatches.
 */
#ifndef SKINPACK_CODEC_OSS_WIDE_H
#define SKINPACK_CODEC_OSS_WIDE_H

#include "codec_internal.h"

/* Encode `count` vertices of k weights (significant may be NULL) or decode `count` codes, whole
 * blocks only (8 lanes for AVX-512, 4 for AVX2), bit-identical to sp_oss_encode_one and
 * sp_oss_decode_one; return how many leading vertices were done. Decode stops before a block
 * holding a code above max_code; with stream set, and weights aligned as the ISA's streaming
 * stores need, it stores them by those and fences them (codec_oss_simd.h's prefetch_decode).
 * Call only where sp_cpu_isa() has the ISA and
 * codec_oss_batch.c's oss_lanes_for allows it. The types are those of every per-ISA path
 * (codec_internal.h's sp_oss_encode_avx2 ... too), and of the dispatch's pointers. */
typedef size_t sp_oss_encode_path(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                                  uint8_t* significant);
typedef size_t sp_oss_decode_path(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                                  int stream);
sp_oss_encode_path sp_oss_wide_encode_avx2, sp_oss_wide_encode_avx512;
sp_oss_decode_path sp_oss_wide_decode_avx2, sp_oss_wide_decode_avx512;

#endif
