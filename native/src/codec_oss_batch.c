/*
 * OSS batch dispatch: which vector path takes a prefix of a batch, for which codecs. The
 * double-lane paths (codec_oss_simd.h) are exact where every OSS intermediate stays below 2^50;
 * past that the wide paths (codec_oss_wide_simd.h) run the layer and row bases in 64-bit integer
 * lanes, up to 64-bit codes. Both per ISA in codec_oss_batch_avx512.c and codec_oss_batch_avx2.c.
 * K = 2 encode past N = 2^49 runs sp_grid_round_pair's exact rounding in the wide driver's
 * double lanes (FMA residuals for its 128-bit products).
 */
#include "codec_internal.h"
#include "codec_oss_wide.h"

/* The widest path this CPU, the caller and the codec allow. */
static sp_isa batch_isa(sp_oss_lanes lanes, sp_isa widest)
{
    if (lanes == SP_LANES_NONE) return SP_ISA_SCALAR;
    sp_isa cpu = sp_cpu_isa();
    return cpu < widest ? cpu : widest;
}

/* Each ISA takes both ways, K = 2 encode past 2^50 grids too (codec_oss_wide_simd.h). */
int sp_oss_batch_supported(const sp_codec* codec, sp_isa widest)
{
    return batch_isa(sp_oss_lanes_for(codec), widest) > SP_ISA_SCALAR;
}

/* AVX-512 takes blocks of 8, AVX2 what is left in blocks of 4 (the tail, or the rest after a
 * block the AVX-512 loop stopped at), the scalar loop in codec.c the remainder. Nothing left:
 * no AVX2 call, whose pointer arithmetic on the null arrays of an empty batch is undefined. */
size_t sp_oss_encode_batch(const sp_codec* codec, const float* weights, size_t count, uint64_t* codes,
                           uint8_t* significant, sp_isa widest)
{
    size_t done = 0;
#if SP_X86_SIMD
    sp_oss_lanes lanes = sp_oss_lanes_for(codec);
    sp_isa isa = batch_isa(lanes, widest);
    sp_oss_encode_path* avx512 = lanes == SP_LANES_WIDE ? sp_oss_wide_encode_avx512 : sp_oss_encode_avx512;
    sp_oss_encode_path* avx2 = lanes == SP_LANES_WIDE ? sp_oss_wide_encode_avx2 : sp_oss_encode_avx2;
    if (isa >= SP_ISA_AVX512) done = avx512(codec, weights, count, codes, significant);
    if (isa >= SP_ISA_AVX2 && done < count)
        done += avx2(codec, weights + done * codec->influences, count - done, codes + done,
                     significant ? significant + done : NULL);
#else
    (void)codec, (void)weights, (void)count, (void)codes, (void)significant, (void)widest, (void)batch_isa;
#endif
    return done;
}

/*
 * Decode batches whose weights take at least this many bytes store them by streaming stores
 * (codec_oss_simd.h's prefetch_decode), as glibc's memcpy does past its non-temporal threshold:
 * outputs that large leave the caches behind anyway, while a mesh of ~100k vertices (1.6 MB of
 * K = 4 weights), read right after its decode, stays below and in the cache.
 */
#define STREAM_MIN_BYTES ((size_t)4 << 20)
#define STREAM_LINE 64

/* How many vertices precede the first one whose weights start a cache line, so that the
 * streaming stores from there write whole lines (and AVX-512's are aligned); count if none does
 * within a line's worth (K = 4 weights not 16-byte aligned, K = 2 ones not 8-byte aligned). */
static size_t stream_head(const float* weights, uint32_t k, size_t count)
{
    for (size_t v = 0; v < count && v < STREAM_LINE / sizeof(float); ++v)
        if (!((uintptr_t)(weights + v * k) % STREAM_LINE)) return v;
    return count;
}

size_t sp_oss_decode_batch_streaming(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights,
                                     sp_isa widest, size_t stream_min_bytes, size_t* streamed)
{
    size_t done = 0;
    if (streamed) *streamed = 0;
#if SP_X86_SIMD
    sp_oss_lanes lanes = sp_oss_lanes_for(codec);
    sp_isa isa = batch_isa(lanes, widest);
    uint32_t k = codec->influences;
    if (isa < SP_ISA_AVX2 || !count) return 0; /* no pointer arithmetic on an empty batch's null arrays */
    sp_oss_decode_path* avx512 = lanes == SP_LANES_WIDE ? sp_oss_wide_decode_avx512 : sp_oss_decode_avx512;
    sp_oss_decode_path* avx2 = lanes == SP_LANES_WIDE ? sp_oss_wide_decode_avx2 : sp_oss_decode_avx2;
    int large = count * k * sizeof(float) >= stream_min_bytes;
    size_t head = large ? stream_head(weights, k, count) : count;
    int stream = head < count;
    if (stream) { /* the head by the scalar code, which stops at an invalid code (the caller reports it) */
        done = sp_oss_decode_scalar(codec, codes, 0, head, weights);
        if (done < head) return done;
    }
    if (isa >= SP_ISA_AVX512) done += avx512(codec, codes + done, count - done, weights + done * k, stream);
    if (done < count) done += avx2(codec, codes + done, count - done, weights + done * k, stream);
    if (streamed && stream) *streamed = done - head;
#else
    (void)codec, (void)codes, (void)count, (void)weights, (void)widest, (void)stream_min_bytes, (void)stream_head;
#endif
    return done;
}

size_t sp_oss_decode_batch(const sp_codec* codec, const uint64_t* codes, size_t count, float* weights, sp_isa widest)
{
    return sp_oss_decode_batch_streaming(codec, codes, count, weights, widest, STREAM_MIN_BYTES, NULL);
}
