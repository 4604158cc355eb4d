/*
 * platform.h's two-halves sp_u128 (what compilers without unsigned __int128 build, such as
 * MSVC) against the compiler's 128-bit type on random and edge operands. The library itself is
 * also built that way for the OSS and codec tests (tests/unit/CMakeLists.txt).
 */
#define SP_PORTABLE_U128 1
#include "../../native/src/platform.h"
#include "check.h"

#if defined(__SIZEOF_INT128__)
typedef unsigned __int128 native_u128;

static native_u128 native_of(sp_u128 x)
{
    return ((native_u128)x.hi << 64) | x.lo;
}

static sp_u128 portable_of(native_u128 x)
{
    sp_u128 r = {(uint64_t)x, (uint64_t)(x >> 64)};
    return r;
}

/* Operands with every interesting shape: small, one half only, near the carries, random. */
static native_u128 operand(void)
{
    uint64_t r = rng_next(), shape = r % 6, lo = rng_next(), hi = rng_next();
    switch (shape) {
    case 0: return lo % 1000;
    case 1: return lo;
    case 2: return (native_u128)hi << 64;
    case 3: return ((native_u128)UINT64_MAX << 64 | UINT64_MAX) - lo % 4;
    case 4: return (native_u128)(hi >> (r % 64)) << 64 | lo;
    default: return (native_u128)hi << 64 | lo;
    }
}

static void matches_native(void)
{
    for (int i = 0; i < 400000; ++i) {
        native_u128 a = operand(), b = operand();
        sp_u128 pa = portable_of(a), pb = portable_of(b);
        CHECK(native_of(sp_u128_add(pa, pb)) == a + b);
        CHECK(native_of(sp_u128_sub(pa, pb)) == a - b);
        CHECK(native_of(sp_u128_mul(pa, pb)) == a * b);
        CHECK(native_of(sp_u128_mul64((uint64_t)a, (uint64_t)b)) == (native_u128)(uint64_t)a * (uint64_t)b);
        CHECK(sp_u128_less(pa, pb) == (a < b));
        if (b) CHECK(native_of(sp_u128_div(pa, pb)) == a / b);
        uint64_t small = (uint64_t)b % 16 + 1;
        CHECK(native_of(sp_u128_div_u64(pa, small)) == a / small);
        double d = sp_u128_to_double(pa), exact = (double)a;
        CHECK(d == exact || (d - exact) * (d - exact) <= exact * exact * 0x1p-104); /* within an ulp */
        if (check_failures > 5) return;
    }
    for (uint32_t bits = 0; bits < 128; ++bits) CHECK(native_of(sp_u128_pow2(bits)) == (native_u128)1 << bits);
    CHECK(sp_u128_low(sp_u128_from(7)) == 7 && sp_u128_high(sp_u128_from(7)) == 0);
}
#endif

int main(void)
{
#if defined(__SIZEOF_INT128__)
    matches_native();
#endif
    return check_report("test_platform");
}
