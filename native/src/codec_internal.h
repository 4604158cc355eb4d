/* Private helpers shared by the codec sources. Not part of the public API. */
#ifndef SKINPACK_CODEC_INTERNAL_H
#define SKINPACK_CODEC_INTERNAL_H

#include "skinpack.h"

/* 128-bit intermediates: the OSS closed forms overflow 64 bits for budgets near 64 bits. */
typedef unsigned __int128 sp_u128;

/* Float rounding of the input weights and of the decoded floats, added to every bound. */
#define SP_FLOAT_SLACK 3.6e-7

/* Largest-remainder rounding of k weights (sorted, summing to ~1) to integers q summing to s. */
void sp_grid_quantize(const float* weights, uint32_t k, uint64_t s, uint64_t* q);

/* Fixed/Cube/POT: pack and unpack the integer grid coordinates q[0..k-1] (q[0] = largest). */
uint64_t sp_grid_pack(const sp_codec* codec, const uint64_t* q);
void sp_grid_unpack(const sp_codec* codec, uint64_t code, uint64_t* q);

/* OSS: simplex index of grid coordinates and back (q[0] is implied by the others). */
uint64_t sp_oss_pack(uint64_t n, uint32_t k, const uint64_t* q);
void sp_oss_unpack(uint64_t n, uint32_t k, uint64_t code, uint64_t* q);

/* Any AABB works on floats directly (its axes do not share a grid). */
uint64_t sp_any_encode(const sp_codec* codec, const float* weights);
void sp_any_decode(const sp_codec* codec, uint64_t code, float* weights);

/* Finish a codec description (code_bits, bits, bounds) once method-specific fields are set. */
sp_result sp_any_configure(uint32_t influences, const uint64_t* axis_samples, sp_codec* codec);

/* Number of codes per method and parameter, or 0 when it does not fit in 64 bits. */
sp_u128 sp_oss_code_count(uint64_t n, uint32_t k);

#endif
