/*
 * The AVX2 + FMA3 OSS batch paths, one translation unit: this ISA's primitives
 * (codec_oss_prim_avx2.h) under the double-lane driver (codec_oss_simd.h) and the wide one for
 * codes past its exact range (codec_oss_wide_simd.h), which share its rounding and root estimates.
 */
#include "codec_internal.h"

#if SP_X86_SIMD
#include "codec_oss_wide.h"
#include "codec_oss_prim_avx2.h"

#include "codec_oss_simd.h"
#include "codec_oss_wide_simd.h"
#else
typedef int sp_no_avx2_path; /* ISO C: no empty translation unit */
#endif
