/*
 * Compiler portability for the library sources (internal): forced inlining, per-function ISA
 * targets, loop unrolling hints, and unsigned 128-bit arithmetic. The public header promises a
 * Windows DLL build, so nothing outside this file names __attribute__, _Pragma("GCC ...") or
 * unsigned __int128 directly.
 */
#ifndef SKINPACK_PLATFORM_H
#define SKINPACK_PLATFORM_H

#include <stdint.h>

/* A static function the compiler must inline (hot per-vertex helpers with constant K). */
#if defined(_MSC_VER) && !defined(__clang__)
#define SP_INLINE static __forceinline
#elif defined(__GNUC__) || defined(__clang__)
#define SP_INLINE static inline __attribute__((always_inline))
#else
#define SP_INLINE static inline
#endif

/* The x86 vector paths need per-function ISA targets (GCC, clang); other compilers and CPUs
 * build the scalar paths only. */
#if (defined(__x86_64__) || defined(__i386__)) && (defined(__GNUC__) || defined(__clang__))
#define SP_X86_SIMD 1
#define SP_TARGET(isa) __attribute__((target(isa)))
#define SP_UNROLL _Pragma("GCC unroll 4")
/* The compiler forgets what the object x holds, so its stores happen and later reads load it
 * (a vector path that means to go through memory, where the compiler would forward in registers). */
#define SP_FORGET(x) __asm__("" : "+m"(x))
/* A hint to bring the cache line at address p into the caches (never faults, whatever p is). */
#define SP_PREFETCH(p) __builtin_prefetch(p)
#else
#define SP_X86_SIMD 0
#define SP_TARGET(isa)
#define SP_UNROLL
#define SP_FORGET(x) ((void)0)
#define SP_PREFETCH(p) ((void)0)
#endif

/* Index of the lowest set bit of x, which is not 0. */
#if defined(__GNUC__) || defined(__clang__)
static inline unsigned sp_lowest_bit64(uint64_t x)
{
    return (unsigned)__builtin_ctzll(x);
}
#else
static inline unsigned sp_lowest_bit64(uint64_t x)
{
    unsigned n = 0;
    for (; !(x & 1); x >>= 1)
        ++n;
    return n;
}
#endif

/* From here to the end of the file, every product and sum rounds on its own: the vector paths
 * must round as the scalar code does, and with FMA enabled both compilers would fuse some (GCC's
 * gnu11 default contracts across statements). Explicit FMA intrinsics stay where they are exact
 * or estimates. */
#if defined(__clang__)
#define SP_FP_CONTRACT_OFF _Pragma("STDC FP_CONTRACT OFF")
#elif defined(__GNUC__)
#define SP_FP_CONTRACT_OFF _Pragma("GCC optimize(\"fp-contract=off\")")
#else
#define SP_FP_CONTRACT_OFF
#endif

/*
 * Unsigned 128-bit integers for the OSS closed forms near 64-bit codes and the codec searches.
 * The compiler's type where it has one; elsewhere (MSVC) two 64-bit halves. Both expose the same
 * functions, so callers never use operators on sp_u128. Defining SP_PORTABLE_U128 selects the
 * two-halves form everywhere (the unit tests check it against the compiler's type).
 */
#if defined(__SIZEOF_INT128__) && !defined(SP_PORTABLE_U128)
typedef unsigned __int128 sp_u128;

static inline sp_u128 sp_u128_from(uint64_t x) { return x; }
static inline sp_u128 sp_u128_pow2(uint32_t bits) { return (sp_u128)1 << bits; } /* bits < 128 */
static inline sp_u128 sp_u128_add(sp_u128 a, sp_u128 b) { return a + b; }
static inline sp_u128 sp_u128_sub(sp_u128 a, sp_u128 b) { return a - b; }
static inline sp_u128 sp_u128_mul(sp_u128 a, sp_u128 b) { return a * b; } /* modulo 2^128 */
static inline sp_u128 sp_u128_div(sp_u128 a, sp_u128 b) { return a / b; } /* b != 0 */
static inline int sp_u128_less(sp_u128 a, sp_u128 b) { return a < b; }
static inline uint64_t sp_u128_low(sp_u128 a) { return (uint64_t)a; }
static inline uint64_t sp_u128_high(sp_u128 a) { return (uint64_t)(a >> 64); }
static inline double sp_u128_to_double(sp_u128 a) { return (double)a; }
#else
typedef struct sp_u128 {
    uint64_t lo, hi;
} sp_u128;

static inline sp_u128 sp_u128_from(uint64_t x)
{
    sp_u128 r = {x, 0};
    return r;
}

static inline sp_u128 sp_u128_pow2(uint32_t bits)
{
    sp_u128 r = {bits < 64 ? (uint64_t)1 << bits : 0, bits >= 64 ? (uint64_t)1 << (bits - 64) : 0};
    return r;
}

static inline sp_u128 sp_u128_add(sp_u128 a, sp_u128 b)
{
    sp_u128 r = {a.lo + b.lo, a.hi + b.hi + (a.lo + b.lo < a.lo)};
    return r;
}

static inline sp_u128 sp_u128_sub(sp_u128 a, sp_u128 b)
{
    sp_u128 r = {a.lo - b.lo, a.hi - b.hi - (a.lo < b.lo)};
    return r;
}

/* The full 128-bit product of two 64-bit numbers from 32-bit halves. */
static inline sp_u128 sp_u128_mul64(uint64_t a, uint64_t b)
{
    uint64_t a0 = (uint32_t)a, a1 = a >> 32, b0 = (uint32_t)b, b1 = b >> 32;
    uint64_t low = a0 * b0, mid1 = a1 * b0, mid2 = a0 * b1, high = a1 * b1;
    uint64_t mid = (low >> 32) + (uint32_t)mid1 + (uint32_t)mid2;
    sp_u128 r = {(mid << 32) | (uint32_t)low, high + (mid1 >> 32) + (mid2 >> 32) + (mid >> 32)};
    return r;
}

static inline sp_u128 sp_u128_mul(sp_u128 a, sp_u128 b) /* modulo 2^128 */
{
    sp_u128 r = sp_u128_mul64(a.lo, b.lo);
    r.hi += a.lo * b.hi + a.hi * b.lo;
    return r;
}

static inline int sp_u128_less(sp_u128 a, sp_u128 b)
{
    return a.hi < b.hi || (a.hi == b.hi && a.lo < b.lo);
}

/* Shift-and-subtract division, b != 0: configuration searches and the widest OSS codes only. */
static inline sp_u128 sp_u128_div(sp_u128 a, sp_u128 b)
{
    sp_u128 quotient = {0, 0}, rest = {0, 0};
    for (int bit = 127; bit >= 0; --bit) {
        rest.hi = (rest.hi << 1) | (rest.lo >> 63);
        rest.lo = (rest.lo << 1) | ((bit >= 64 ? a.hi >> (bit - 64) : a.lo >> bit) & 1);
        if (!sp_u128_less(rest, b)) {
            rest = sp_u128_sub(rest, b);
            if (bit >= 64) quotient.hi |= (uint64_t)1 << (bit - 64);
            else quotient.lo |= (uint64_t)1 << bit;
        }
    }
    return quotient;
}

static inline uint64_t sp_u128_low(sp_u128 a) { return a.lo; }
static inline uint64_t sp_u128_high(sp_u128 a) { return a.hi; }
static inline double sp_u128_to_double(sp_u128 a) { return (double)a.hi * 18446744073709551616.0 + (double)a.lo; }
#endif

/* Shorthands for the common mixed forms. */
static inline sp_u128 sp_u128_mul_u64(sp_u128 a, uint64_t b) { return sp_u128_mul(a, sp_u128_from(b)); }
static inline sp_u128 sp_u128_add_u64(sp_u128 a, uint64_t b) { return sp_u128_add(a, sp_u128_from(b)); }
static inline sp_u128 sp_u128_div_u64(sp_u128 a, uint64_t b) { return sp_u128_div(a, sp_u128_from(b)); }

/* floor(a / b) and a mod b where the quotient fits 64 bits (b > a's high half), as x86-64's DIV
 * does it in one instruction (the compiler's 128-bit division is a library call that cannot
 * assume the bound). SP_NARROW_DIVIDE says whether it is there: callers keep a portable route,
 * which the two-halves build (SP_PORTABLE_U128) takes. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(SP_PORTABLE_U128)
#define SP_NARROW_DIVIDE 1
static inline uint64_t sp_u128_divide_narrow(sp_u128 a, uint64_t b, uint64_t* remainder)
{
    uint64_t quotient, rest;
    __asm__("divq %4" : "=a"(quotient), "=d"(rest) : "a"(sp_u128_low(a)), "d"(sp_u128_high(a)), "rm"(b) : "cc");
    *remainder = rest;
    return quotient;
}
#else
#define SP_NARROW_DIVIDE 0
#endif

#endif
