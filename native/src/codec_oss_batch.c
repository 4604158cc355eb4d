/*
 * OSS batch dispatch: which vector path (codec_oss_batch_avx512.c, codec_oss_batch_avx2.c, one
 * driver in codec_oss_simd.h) takes a prefix of a batch, for which codecs. The paths are exact
 * where every OSS intermediate stays below 2^50 in double lanes; wider codes take the scalar
 * loop in codec.c.
 */
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

int sp_oss_batch_supported(const sp_codec* codec)
{
    uint32_t k = codec->influences;
    if (codec->method != SP_METHOD_OSS || k < 2 || k > 4) return 0;
    uint64_t limit = k == 2 ? BATCH_MAX_N2 : (k == 3 ? BATCH_MAX_N3 : BATCH_MAX_N4);
    return codec->n >= 2 && codec->n <= limit;
}

/* The widest path this CPU, the caller and the codec allow. */
static sp_isa batch_isa(const sp_codec* codec, sp_isa widest)
{
    if (!sp_oss_batch_supported(codec)) return SP_ISA_SCALAR;
    sp_isa cpu = sp_cpu_isa();
    return cpu < widest ? cpu : widest;
}

/* AVX-512 takes blocks of 8, AVX2 what is left in blocks of 4 (the tail, or the rest after a
 * block the AVX-512 loop stopped at), the scalar loop in codec.c the remainder. Nothing left:
 * no AVX2 call, whose pointer arithmetic on the null arrays of an empty batch is undefined. */
size_t sp_oss_encode_batch(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                           uint8_t* significant, sp_isa widest)
{
    size_t done = 0;
#if SP_X86_SIMD
    sp_isa isa = batch_isa(codec, widest);
    if (isa >= SP_ISA_AVX512) done = sp_oss_encode_avx512(codec, weights, count, codes, significant);
    if (isa >= SP_ISA_AVX2 && done < count)
        done += sp_oss_encode_avx2(codec, weights + done * codec->influences, count - done, codes + done,
                                   significant ? significant + done : NULL);
#else
    (void)codec, (void)weights, (void)count, (void)codes, (void)significant, (void)widest, (void)batch_isa;
#endif
    return done;
}

size_t sp_oss_decode_batch(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, sp_isa widest)
{
    size_t done = 0;
#if SP_X86_SIMD
    sp_isa isa = batch_isa(codec, widest);
    if (isa >= SP_ISA_AVX512) done = sp_oss_decode_avx512(codec, codes, count, weights);
    if (isa >= SP_ISA_AVX2 && done < count)
        done += sp_oss_decode_avx2(codec, codes + done, count - done, weights + done * codec->influences);
#else
    (void)codec, (void)codes, (void)count, (void)weights, (void)widest;
#endif
    return done;
}
