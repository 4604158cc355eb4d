/*
 * CPU feature detection for the vector paths: cpuid and xgetbv once, cached. Both the CPU and
 * the OS must support an ISA: a CPU with AVX-512 under an OS that does not save zmm registers
 * must take the AVX2 (or scalar) path.
 */
#include "cpu_features.h"

#include "platform.h"

#if SP_X86_SIMD
#include <cpuid.h>
#include <stdint.h>

static void cpuid(uint32_t leaf, uint32_t subleaf, uint32_t* r)
{
    __cpuid_count(leaf, subleaf, r[0], r[1], r[2], r[3]);
}

/* XCR0: which register states the OS saves (xgetbv as an instruction: no -mxsave needed). */
static uint64_t os_saved_state(void)
{
    uint32_t lo, hi;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    return ((uint64_t)hi << 32) | lo;
}

sp_isa sp_cpu_isa_detect(void)
{
    uint32_t r[4];
    cpuid(0, 0, r);
    if (r[0] < 7) return SP_ISA_SCALAR;
    cpuid(1, 0, r);
    int fma = (r[2] >> 12) & 1, osxsave = (r[2] >> 27) & 1, avx = (r[2] >> 28) & 1;
    if (!osxsave || !avx) return SP_ISA_SCALAR;
    uint64_t xcr0 = os_saved_state();
    if ((xcr0 & 0x6) != 0x6) return SP_ISA_SCALAR; /* xmm and ymm state */
    cpuid(7, 0, r);
    int avx2 = (r[1] >> 5) & 1, avx512f = (r[1] >> 16) & 1, avx512dq = (r[1] >> 17) & 1, avx512vl = (r[1] >> 31) & 1;
    if (!avx2 || !fma) return SP_ISA_SCALAR;
    if (avx512f && avx512dq && avx512vl && (xcr0 & 0xE0) == 0xE0) return SP_ISA_AVX512; /* opmask, zmm 0-15, 16-31 */
    return SP_ISA_AVX2;
}
#else
sp_isa sp_cpu_isa_detect(void)
{
    return SP_ISA_SCALAR; /* no vector paths in this build */
}
#endif

#if !defined(__STDC_NO_ATOMICS__)
#include <stdatomic.h>

sp_isa sp_cpu_isa(void)
{
    /* -1: not read yet. Two threads may both detect on the first call; they store the same. */
    static atomic_int cached = -1;
    int isa = atomic_load_explicit(&cached, memory_order_relaxed);
    if (isa < 0) {
        isa = (int)sp_cpu_isa_detect();
        atomic_store_explicit(&cached, isa, memory_order_relaxed);
    }
    return (sp_isa)isa;
}
#else
sp_isa sp_cpu_isa(void)
{
    return sp_cpu_isa_detect(); /* no C11 atomics: detect each time rather than race */
}
#endif
