// skinpack_decode.glsl - GPU decoders for the skinpack bit layout (docs/format.md).
//
// Include after defining the optional buffer hooks the shader wants:
//   SP_TUPLE_LUT_WORD(i)     word i of the tuple LUT buffer   -> sp_lut_joints()
//   SP_MESHLET_WORD(i)       word i of the sp_meshlet records  -> sp_load_meshlet()
//   SP_MESHLET_DATA_WORD(i)  word i of the meshlet byte arrays -> sp_meshlet_*()
// (GLSL cannot pass buffers to functions; the hooks keep bindings in the shader that owns them.)
//
// Two decoders, chosen per codec by sp_codec_is_narrow():
//   * narrow: plain 32-bit uint arithmetic. Exact whenever every intermediate stays below 2^32:
//     OSS codes of up to 28 bits (K = 4) or 30 bits (K = 3) - the Paper's 22-bit configuration
//     and every OSS K = 4 vertex word of 32 bits with a tuple index of 4+ bits - and any other
//     code whose value, grid denominator and axis counts fit 32 bits.
//   * wide: 64-bit values as uvec2 (x = low half, y = high half), 128-bit products as uvec4,
//     built on uaddCarry/umulExtended. Needs no shaderInt64, so one code path runs everywhere;
//     it is the Paper's "64-bit arithmetic" case (48-bit words, 38-bit weight codes). For OSS
//     K = 4 with S(N) < 2^32 (codes of up to 46 bits, SP_GPU_CODEC_ROWS32) only the layer step
//     runs in 64 bits; the row step runs on 32-bit in-layer values.
// Both produce the exact integers q_i of format.md (x_i for Any), then float weights.

#ifndef SKINPACK_DECODE_GLSL
#define SKINPACK_DECODE_GLSL

#include "skinpack_constants.glsl"
#include "skinpack_gpu_layout.h"

// ---- 64-bit and 128-bit unsigned helpers ------------------------------------------------

uvec2 sp_u64_add(uvec2 a, uvec2 b)
{
    uint carry;
    uint low = uaddCarry(a.x, b.x, carry);
    return uvec2(low, a.y + b.y + carry);
}

uvec2 sp_u64_sub(uvec2 a, uvec2 b)
{
    uint borrow;
    uint low = usubBorrow(a.x, b.x, borrow);
    return uvec2(low, a.y - b.y - borrow);
}

bool sp_u64_less_equal(uvec2 a, uvec2 b)
{
    return a.y < b.y || (a.y == b.y && a.x <= b.x);
}

// Shifts by 0..63 (GLSL leaves shifts by 32 undefined, hence the branches).
uvec2 sp_u64_shift_left(uvec2 a, uint n)
{
    if (n == 0u) return a;
    if (n >= 32u) return uvec2(0u, a.x << (n - 32u));
    return uvec2(a.x << n, (a.y << n) | (a.x >> (32u - n)));
}

uvec2 sp_u64_shift_right(uvec2 a, uint n)
{
    if (n == 0u) return a;
    if (n >= 32u) return uvec2(a.y >> (n - 32u), 0u);
    return uvec2((a.x >> n) | (a.y << (32u - n)), a.y >> n);
}

// The lowest n bits of a, n = 0..64.
uvec2 sp_u64_low_bits(uvec2 a, uint n)
{
    if (n >= 64u) return a;
    if (n >= 32u) return uvec2(a.x, n == 32u ? 0u : a.y & ((1u << (n - 32u)) - 1u));
    return uvec2(n == 0u ? 0u : a.x & (0xffffffffu >> (32u - n)), 0u);
}

uvec2 sp_u64_mul32(uint a, uint b)
{
    uint high, low;
    umulExtended(a, b, high, low);
    return uvec2(low, high);
}

uvec4 sp_u128_add(uvec4 a, uvec4 b)
{
    uint c0, c1, c2, c1b, c2b;
    uint x = uaddCarry(a.x, b.x, c0);
    uint y = uaddCarry(a.y, b.y, c1);
    y = uaddCarry(y, c0, c1b);
    uint z = uaddCarry(a.z, b.z, c2);
    z = uaddCarry(z, c1 + c1b, c2b);
    return uvec4(x, y, z, a.w + b.w + c2 + c2b);
}

uvec4 sp_u128_mul(uvec2 a, uvec2 b)
{
    uint high, low;
    umulExtended(a.x, b.x, high, low);
    uvec4 product = uvec4(low, high, 0u, 0u);
    umulExtended(a.x, b.y, high, low);
    product = sp_u128_add(product, uvec4(0u, low, high, 0u));
    umulExtended(a.y, b.x, high, low);
    product = sp_u128_add(product, uvec4(0u, low, high, 0u));
    umulExtended(a.y, b.y, high, low);
    return sp_u128_add(product, uvec4(0u, 0u, low, high));
}

// floor(a / d) for a small divisor (d < 2^16): schoolbook division in 16-bit digits, so every
// partial dividend (remainder << 16 | digit) fits 32 bits.
uvec4 sp_u128_div_small(uvec4 a, uint d)
{
    uvec4 quotient = uvec4(0u);
    uint remainder = 0u;
    for (int limb = 3; limb >= 0; --limb) {
        uint high = (remainder << 16) | (a[limb] >> 16);
        remainder = high % d;
        uint low = (remainder << 16) | (a[limb] & 0xffffu);
        remainder = low % d;
        quotient[limb] = ((high / d) << 16) | (low / d);
    }
    return quotient;
}

// a / d and a % d for 64-bit operands by restoring binary long division, starting at the
// highest set bit of a. Only Any with codes over 32 bits needs it (the Paper's slow case).
uvec2 sp_u64_divmod(uvec2 a, uvec2 d, out uvec2 remainder)
{
    uvec2 quotient = uvec2(0u);
    remainder = uvec2(0u);
    int top = a.y != 0u ? 32 + findMSB(a.y) : findMSB(a.x);
    for (int bit = top; bit >= 0; --bit) {
        uint incoming = bit >= 32 ? (a.y >> uint(bit - 32)) & 1u : (a.x >> uint(bit)) & 1u;
        bool overflow = (remainder.y >> 31) != 0u; // remainder * 2 would leave 64 bits
        remainder = sp_u64_shift_left(remainder, 1u) | uvec2(incoming, 0u);
        if (overflow || sp_u64_less_equal(d, remainder)) {
            remainder = sp_u64_sub(remainder, d);
            quotient |= sp_u64_shift_left(uvec2(1u, 0u), uint(bit));
        }
    }
    return quotient;
}

float sp_u64_to_float(uvec2 a)
{
    return float(a.y) * 4294967296.0 + float(a.x);
}

// ---- codec configuration ------------------------------------------------------------------

uint sp_codec_method(SpGpuCodec codec) { return codec.config.x; }
uint sp_codec_influences(SpGpuCodec codec) { return codec.config.y; }
uint sp_codec_weight_bits(SpGpuCodec codec) { return codec.config.z; }
uint sp_codec_tuple_bits(SpGpuCodec codec) { return codec.config.w; }
uint sp_codec_words_per_vertex(SpGpuCodec codec) { return codec.packing.x; }

// True when the 32-bit decoder is exact for this codec (skinpack_gpu_layout.h explains the limits).
bool sp_codec_is_narrow(SpGpuCodec codec)
{
    return SP_GPU_CODEC_IS_NARROW(codec);
}

// ---- OSS closed forms (format.md section 2) --------------------------------------------
// sN(j) = floor((j (4N - 3j + 2) + 1) / 4); u(k) = floor((3Nk(N - 2k + 3) + k(4k^2 - 9k + 6) + 2) / 9).
// Both are written with non-negative factors only (4N + 2 > 3j for every row, N + 3 > 2k for
// every layer, 4k^2 - 9k + 6 > 0 always) so unsigned arithmetic never wraps.

uint sp_oss_row_base32(uint n, uint j)
{
    return (j * (4u * n + 2u - 3u * j) + 1u) / 4u;
}

uint sp_oss_layer_base32(uint n, uint k)
{
    return (3u * n * k * (n + 3u - 2u * k) + k * (4u * k * k + 6u - 9u * k) + 2u) / 9u;
}

uvec2 sp_oss_row_base64(uvec2 n, uvec2 j)
{
    uvec2 factor = sp_u64_sub(sp_u64_add(sp_u64_shift_left(n, 2u), uvec2(2u, 0u)),
                              sp_u64_add(sp_u64_shift_left(j, 1u), j));
    uvec4 numerator = sp_u128_add(sp_u128_mul(j, factor), uvec4(1u, 0u, 0u, 0u));
    return uvec2((numerator.x >> 2) | (numerator.y << 30), (numerator.y >> 2) | (numerator.z << 30));
}

// K = 4 codes of at most 64 bits have N < 2^23, so n and k fit 32 bits; the numerator does not.
uvec2 sp_oss_layer_base64(uint n, uint k)
{
    uvec4 sheared = sp_u128_mul(sp_u64_mul32(3u * n, k), uvec2(n + 3u - 2u * k, 0u));
    uvec2 quadratic = sp_u64_sub(sp_u64_add(sp_u64_mul32(4u * k, k), uvec2(6u, 0u)), sp_u64_mul32(9u, k));
    uvec4 cubic = sp_u128_mul(quadratic, uvec2(k, 0u));
    uvec4 numerator = sp_u128_add(sp_u128_add(sheared, cubic), uvec4(2u, 0u, 0u, 0u));
    return sp_u128_div_small(numerator, 9u).xy;
}

// ---- In-layer 32-bit forms (K = 4 wide codes while S(N) < 2^32, up to 46-bit codes) -------
// Past 28 bits only the layer step needs 64 bits: every in-layer index is below S(N), so with
// S(N) < 2^32 (SP_GPU_CODEC_ROWS32) the row step runs on 32-bit values computed modulo 2^32
// (the Authors' split).

// sB(j) = jB - ceil((3j + 1)(j - 1) / 4) modulo 2^32: exact for every row, as sB(j) < 2^32;
// the 34-bit product comes from umulExtended.
uint sp_oss_row_base_in_layer32(uint b, uint j)
{
    if (j == 0u) return 0u;
    uint high, low, carry;
    umulExtended(3u * j + 1u, j - 1u, high, low);
    low = uaddCarry(low, 3u, carry);
    return j * b - ((low >> 2) | ((high + carry) << 30));
}

// S(B) and (B^2 + B + 1) mod 3 for S(B) < 2^32 in 32 bits: with B = 3t + e,
// S(B) = 3t^2 + (2e + 1) t + e and the remainder is 0 for e = 1, else 1.
uint sp_oss_triangle_count_in_layer32(uint b, out uint remainder)
{
    uint t = b / 3u, e = b - 3u * t;
    remainder = e == 1u ? 0u : 1u;
    return 3u * t * t + (2u * e + 1u) * t + e;
}

// The largest row j in [0, last] with sB(j) <= w (sp_oss_search32 on the in-layer forms).
uint sp_oss_row_search_in_layer32(uint b, uint last, float estimate, uint w)
{
    uint x = estimate >= 0.0 ? uint(min(estimate, float(last))) : 0u; // NaN lands on 0
    x = min(x, last);
    uint low, high;
    if (sp_oss_row_base_in_layer32(b, x) <= w) {
        low = x;
        high = last + 1u;
        for (uint step = 1u; step <= last - low; step <<= 1) {
            if (sp_oss_row_base_in_layer32(b, low + step) > w) {
                high = low + step;
                break;
            }
            low += step;
        }
    } else {
        high = x;
        low = 0u;
        for (uint step = 1u; step < high; step <<= 1) {
            if (sp_oss_row_base_in_layer32(b, high - step) <= w) {
                low = high - step;
                break;
            }
            high -= step;
        }
    }
    while (high - low > 1u) {
        uint middle = low + (high - low) / 2u;
        if (sp_oss_row_base_in_layer32(b, middle) <= w) low = middle;
        else high = middle;
    }
    return low;
}

// S(N) = floor((N^2 + N + 1) / 3), samples in a triangle with N bottom samples.
uvec2 sp_oss_triangle_count64(uvec2 n)
{
    uvec4 numerator = sp_u128_add(sp_u128_mul(n, n), uvec4(sp_u64_add(n, uvec2(1u, 0u)), 0u, 0u));
    return sp_u128_div_small(numerator, 3u).xy;
}

// Estimates. Both mirror the closed form at its apex, as the Paper does, so the root is taken
// of a small exact integer difference instead of a difference of two huge floats.
//
// Row: s~(j*) - s~(j) = 3/4 (j* - j)^2 with j* = (2N + 1)/3, and 12 (s~(j*) - W) =
// 12 (S(N) - W) + 4 ((N^2 + N + 1) mod 3), so j~ = (2N + 1 - sqrt(that)) / 3.
float sp_oss_row_estimate(float n, float count_minus_rest, float triangle_remainder)
{
    return (2.0 * n + 1.0 - sqrt(12.0 * count_minus_rest + 4.0 * triangle_remainder)) / 3.0;
}

// Layer: the Paper's root k~ = (2N + 3 - (c + 1/c)) / 4, c = cbrt(V - 1 + sqrt(V (V - 2))),
// V = 72 (u~((N+1)/2) - U) = 72 (T(N) - U) + delta with 0 <= delta < 78; delta's midpoint
// is used, the search below absorbs the difference.
float sp_oss_layer_estimate(float n, float count_minus_code)
{
    float v = 72.0 * count_minus_code + 39.0;
    float c = pow(v - 1.0 + sqrt(v) * sqrt(v - 2.0), 1.0 / 3.0);
    return (2.0 * n + 3.0 - (c + 1.0 / c)) / 4.0;
}

// Layer of a narrow K = 4 code from one cube root: t = c + 1/c with c = cbrt(x) and
// x = 2(V - 1) = 8M^3 + 12M^2 - 106 - 144 code for code + 17/18 (M = N + 1; the vector paths'
// shifted argument, native/src/codec_oss_simd.h), which puts every code strictly inside its
// layer in exact arithmetic: no square roots, and float error moves the floor by at most one
// layer near a boundary (a float32 emulation of every layer's first and last codes up to the
// narrow limit: one), so one comparison each way fixes it. The fixes are loops, so any error
// still ends on the exact layer. x = 144 (max_code - code) + x(max_code), the latter a small
// number computed modulo 2^32.
uint sp_oss_layer_narrow(uint n, uint max_code, uint code)
{
    uint m = n + 1u, last = (n + 1u) / 2u - 1u;
    uint top = 8u * m * m * m + 12u * m * m - 106u - 144u * max_code; // x(max_code) >= 6
    float x = 144.0 * float(max_code - code) + float(top);
    float c = pow(x, 1.0 / 3.0);
    float estimate = 0.25 * float(2u * n + 3u) - 0.25 * (c + 1.0 / c);
    uint layer = estimate >= 0.0 ? min(uint(estimate), last) : 0u; // NaN lands on 0
    while (layer > 0u && sp_oss_layer_base32(n, layer) > code) --layer;
    while (layer < last && sp_oss_layer_base32(n, layer + 1u) <= code) ++layer;
    return layer;
}

// The largest x in [0, last] with base(x) <= code. base(0) = 0 and base is increasing. Starts at
// the float estimate and gallops (1, 2, 4, ... steps) to a bracket, then bisects: two base
// evaluations when the estimate is right (the Paper's off-by-one check), O(log error) when the
// float estimate of a wide code is off by more.
uint sp_oss_search32(bool layer, uint n, uint last, float estimate, uint code)
{
    uint x = estimate >= 0.0 ? uint(min(estimate, float(last))) : 0u; // NaN lands on 0
    x = min(x, last);
    uint low, high; // base(low) <= code; high == last + 1 or base(high) > code
    if ((layer ? sp_oss_layer_base32(n, x) : sp_oss_row_base32(n, x)) <= code) {
        low = x;
        high = last + 1u;
        for (uint step = 1u; step <= last - low; step <<= 1) {
            uint probe = low + step;
            if ((layer ? sp_oss_layer_base32(n, probe) : sp_oss_row_base32(n, probe)) > code) {
                high = probe;
                break;
            }
            low = probe;
        }
    } else {
        high = x;
        low = 0u;
        for (uint step = 1u; step < high; step <<= 1) {
            uint probe = high - step;
            if ((layer ? sp_oss_layer_base32(n, probe) : sp_oss_row_base32(n, probe)) <= code) {
                low = probe;
                break;
            }
            high = probe;
        }
    }
    while (high - low > 1u) {
        uint middle = low + (high - low) / 2u;
        if ((layer ? sp_oss_layer_base32(n, middle) : sp_oss_row_base32(n, middle)) <= code) low = middle;
        else high = middle;
    }
    return low;
}

uvec2 sp_oss_base64(bool layer, uvec2 n, uvec2 x)
{
    return layer ? sp_oss_layer_base64(n.x, x.x) : sp_oss_row_base64(n, x);
}

// sp_oss_search32 on 64-bit indices (K = 3 codes near 64 bits have more than 2^32 rows).
uvec2 sp_oss_search64(bool layer, uvec2 n, uvec2 last, float estimate, uvec2 code)
{
    uvec2 x = uvec2(0u);
    if (estimate >= 0.0) {
        float clamped = min(estimate, sp_u64_to_float(last));
        x = uvec2(uint(mod(clamped, 4294967296.0)), uint(clamped / 4294967296.0));
    }
    if (!sp_u64_less_equal(x, last)) x = last;
    uvec2 one = uvec2(1u, 0u);
    uvec2 low, high;
    bool high_is_end = false; // high == last + 1, which may not be representable
    if (sp_u64_less_equal(sp_oss_base64(layer, n, x), code)) {
        low = x;
        high_is_end = true;
        for (uvec2 step = one; sp_u64_less_equal(step, sp_u64_sub(last, low)); step = sp_u64_shift_left(step, 1u)) {
            uvec2 probe = sp_u64_add(low, step);
            if (!sp_u64_less_equal(sp_oss_base64(layer, n, probe), code)) {
                high = probe;
                high_is_end = false;
                break;
            }
            low = probe;
            if (step.y >= 0x80000000u) break;
        }
        if (high_is_end) {
            if (low == last) return low;
            high = sp_u64_add(last, one); // last < 2^64 - 1 whenever low < last
        }
    } else {
        high = x;
        low = uvec2(0u);
        for (uvec2 step = one; !sp_u64_less_equal(high, step); step = sp_u64_shift_left(step, 1u)) {
            uvec2 probe = sp_u64_sub(high, step);
            if (sp_u64_less_equal(sp_oss_base64(layer, n, probe), code)) {
                low = probe;
                break;
            }
            high = probe;
        }
    }
    while (!sp_u64_less_equal(sp_u64_sub(high, low), one)) {
        uvec2 middle = sp_u64_add(low, sp_u64_shift_right(sp_u64_sub(high, low), 1u));
        if (sp_u64_less_equal(sp_oss_base64(layer, n, middle), code)) low = middle;
        else high = middle;
    }
    return low;
}

// ---- weight decoders ---------------------------------------------------------------------
// Result: q (q1..qK; zero beyond K) and the float weights w1..w4 (zero beyond K).
// Any has no common grid: q holds x2..xK in slots 2..K (slot 1 is 0) and w1 = 1 - sum.

vec4 sp_grid_weights32(SpGpuCodec codec, uvec4 q)
{
    return vec4(q) * codec.factors.x;
}

// Narrow decoder: the code fits 32 bits and sp_codec_is_narrow(codec) holds.
vec4 sp_decode_weights32(SpGpuCodec codec, uint code, out uvec4 q)
{
    uint method = sp_codec_method(codec);
    uint k = sp_codec_influences(codec);
    q = uvec4(0u);
    if (k == 1u) {
        q.x = codec.n_scale.z;
        return vec4(1.0, 0.0, 0.0, 0.0);
    }
    if (method == SP_METHOD_ANY) {
        vec4 w = vec4(0.0);
        uint rest = code;
        for (uint axis = 0u; axis + 1u < k; ++axis) {
            uint samples = codec.axis_low[axis];
            q[axis + 1u] = rest % samples;
            rest /= samples;
            w[axis + 1u] = float(q[axis + 1u]) * codec.factors[axis];
        }
        w.x = 1.0 - (w.y + w.z + w.w);
        return w;
    }
    uint scale = codec.n_scale.z;
    if (method == SP_METHOD_OSS) {
        uint n = codec.n_scale.x;
        uint layer = 0u, row = 0u, rest = code, bottom = n;
        if (k == 4u) {
            layer = sp_oss_layer_narrow(n, codec.max_code.x, code);
            rest -= sp_oss_layer_base32(n, layer);
            bottom = n - 2u * layer;
        }
        if (k >= 3u) {
            uint triangle_numerator = bottom * bottom + bottom + 1u;
            uint triangle_count = triangle_numerator / 3u;
            uint last_row = (2u * bottom + 1u) / 3u - 1u;
            float estimate = sp_oss_row_estimate(float(bottom), float(triangle_count - rest),
                                                 float(triangle_numerator % 3u));
            row = sp_oss_search32(false, bottom, last_row, estimate, rest);
            rest -= sp_oss_row_base32(bottom, row);
        }
        // rest is now the index i inside the row; shear back (format.md: q4 = k, q3 = j + k, q2 = i + j + k).
        q.w = k == 4u ? layer : 0u;
        q.z = row + layer;
        q.y = rest + row + layer;
        q.x = scale - q.y - q.z - q.w;
        return sp_grid_weights32(codec, q);
    }
    // Fixed stores q1..qK, Cube and POT store q2..qK; component_bits lists the widths in code order.
    uint first = method == SP_METHOD_FIXED ? 0u : 1u;
    uint shift = 0u;
    for (uint slot = first; slot < k; ++slot) {
        uint width = codec.component_bits[slot - first];
        q[slot] = bitfieldExtract(code, int(shift), int(width));
        shift += width;
    }
    if (first == 1u) q.x = scale - (q.y + q.z + q.w);
    return sp_grid_weights32(codec, q);
}

// Wide decoder: any code of up to 64 bits. q_low/q_high are the halves of q1..q4. rows32: take
// the row step in 32 bits, which the caller has checked SP_GPU_CODEC_ROWS32 allows (a constant
// in specialised shaders, so the other row step folds away).
vec4 sp_decode_weights64_rows(SpGpuCodec codec, uvec2 code, bool rows32, out uvec4 q_low, out uvec4 q_high)
{
    uint method = sp_codec_method(codec);
    uint k = sp_codec_influences(codec);
    uvec2 scale = codec.n_scale.zw;
    uvec2 q[4] = uvec2[4](uvec2(0u), uvec2(0u), uvec2(0u), uvec2(0u));
    vec4 w = vec4(0.0);
    if (k == 1u) {
        q[0] = scale;
        w.x = 1.0;
    } else if (method == SP_METHOD_ANY) {
        uvec2 rest = code;
        for (uint axis = 0u; axis + 1u < k; ++axis) {
            uvec2 samples = uvec2(codec.axis_low[axis], codec.axis_high[axis]);
            uvec2 x;
            rest = sp_u64_divmod(rest, samples, x);
            q[axis + 1u] = x;
            w[axis + 1u] = sp_u64_to_float(x) * codec.factors[axis];
        }
        w.x = 1.0 - (w.y + w.z + w.w);
    } else {
        if (method == SP_METHOD_OSS) {
            uvec2 n = codec.n_scale.xy;
            uvec2 layer = uvec2(0u), row, rest = code, bottom = n;
            if (k == 2u) {
                q[1] = code;
            } else {
                if (k == 4u) {
                    uvec2 last_layer = uvec2((n.x + 1u) / 2u - 1u, 0u);
                    float estimate = sp_oss_layer_estimate(sp_u64_to_float(n),
                                                           sp_u64_to_float(sp_u64_sub(codec.max_code.xy, code)) + 1.0);
                    layer = sp_oss_search64(true, n, last_layer, estimate, code);
                    rest = sp_u64_sub(rest, sp_oss_layer_base64(n.x, layer.x));
                    bottom = sp_u64_sub(n, sp_u64_shift_left(layer, 1u));
                }
                if (rows32) { // K = 4 with S(N) < 2^32: the row step in 32 bits
                    uint remainder32, b32 = bottom.x;
                    uint count32 = sp_oss_triangle_count_in_layer32(b32, remainder32);
                    float estimate = sp_oss_row_estimate(float(b32), float(count32 - rest.x), float(remainder32));
                    uint row32 = sp_oss_row_search_in_layer32(b32, (2u * b32 + 1u) / 3u - 1u, estimate, rest.x);
                    uint i32 = rest.x - sp_oss_row_base_in_layer32(b32, row32);
                    q[3] = layer;
                    q[2] = uvec2(row32 + layer.x, 0u);
                    q[1] = uvec2(i32 + row32 + layer.x, 0u);
                } else {
                    uvec2 triangle_count = sp_oss_triangle_count64(bottom);
                    uint triangle_remainder = (bottom.x % 3u + bottom.y % 3u) % 3u; // 2^32 = 1 (mod 3)
                    triangle_remainder = (triangle_remainder * triangle_remainder + triangle_remainder + 1u) % 3u;
                    uvec2 row_count = sp_u128_div_small(uvec4(sp_u64_add(sp_u64_shift_left(bottom, 1u), uvec2(1u, 0u)), 0u, 0u), 3u).xy;
                    float estimate = sp_oss_row_estimate(sp_u64_to_float(bottom),
                                                         sp_u64_to_float(sp_u64_sub(triangle_count, rest)),
                                                         float(triangle_remainder));
                    row = sp_oss_search64(false, bottom, sp_u64_sub(row_count, uvec2(1u, 0u)), estimate, rest);
                    rest = sp_u64_sub(rest, sp_oss_row_base64(bottom, row));
                    q[3] = k == 4u ? layer : uvec2(0u);
                    q[2] = sp_u64_add(row, layer);
                    q[1] = sp_u64_add(rest, q[2]);
                }
            }
        } else {
            uint first = method == SP_METHOD_FIXED ? 0u : 1u;
            uint shift = 0u;
            for (uint slot = first; slot < k; ++slot) {
                uint width = codec.component_bits[slot - first];
                q[slot] = sp_u64_low_bits(sp_u64_shift_right(code, shift), width);
                shift += width;
            }
        }
        if (method != SP_METHOD_FIXED) q[0] = sp_u64_sub(scale, sp_u64_add(sp_u64_add(q[1], q[2]), q[3]));
        for (uint slot = 0u; slot < k; ++slot) w[slot] = sp_u64_to_float(q[slot]) * codec.factors.x;
    }
    q_low = uvec4(q[0].x, q[1].x, q[2].x, q[3].x);
    q_high = uvec4(q[0].y, q[1].y, q[2].y, q[3].y);
    return w;
}

// The wide decoder with the cheapest row step exact for the codec.
vec4 sp_decode_weights64(SpGpuCodec codec, uvec2 code, out uvec4 q_low, out uvec4 q_high)
{
    return sp_decode_weights64_rows(codec, code, SP_GPU_CODEC_ROWS32(codec), q_low, q_high);
}

// Either decoder, whichever is exact for the codec (a uniform branch: all vertices agree).
vec4 sp_decode_weights(SpGpuCodec codec, uvec2 code)
{
    if (sp_codec_is_narrow(codec)) {
        uvec4 q;
        return sp_decode_weights32(codec, code.x, q);
    }
    uvec4 q_low, q_high;
    return sp_decode_weights64(codec, code, q_low, q_high);
}

// ---- vertex words (format.md section 4) --------------------------------------------------
// value = code | tuple_index << weight_bits, in word0 (and word1 when words_per_vertex = 2).

uvec2 sp_vertex_value(SpGpuCodec codec, uint word0, uint word1)
{
    return uvec2(word0, sp_codec_words_per_vertex(codec) == 2u ? word1 : 0u);
}

uvec2 sp_vertex_code(SpGpuCodec codec, uvec2 value)
{
    return sp_u64_low_bits(value, sp_codec_weight_bits(codec));
}

uint sp_vertex_tuple(SpGpuCodec codec, uvec2 value)
{
    return sp_u64_low_bits(sp_u64_shift_right(value, sp_codec_weight_bits(codec)), sp_codec_tuple_bits(codec)).x;
}

// The format requires the bits above tuple_bits + weight_bits to be zero.
bool sp_vertex_padding_is_zero(SpGpuCodec codec, uvec2 value)
{
    uint used = sp_codec_weight_bits(codec) + sp_codec_tuple_bits(codec);
    return used >= 64u || sp_u64_shift_right(value, used) == uvec2(0u);
}

// ---- tuple LUT (format.md section 3) -----------------------------------------------------
// K joints per entry, u8 when the skin has <= 256 joints, else u16, packed little-endian.

#ifdef SP_TUPLE_LUT_WORD
uint sp_lut_joint(SpGpuCodec codec, uint tuple_index, uint slot)
{
    uint element = tuple_index * sp_codec_influences(codec) + slot;
    if (codec.packing.y == 1u) return bitfieldExtract(SP_TUPLE_LUT_WORD(element >> 2), int((element & 3u) * 8u), 8);
    return bitfieldExtract(SP_TUPLE_LUT_WORD(element >> 1), int((element & 1u) * 16u), 16);
}

// Joints of all K slots; slots beyond K read as joint 0 (their weight is 0).
uvec4 sp_lut_joints(SpGpuCodec codec, uint tuple_index)
{
    // K = 4 entries are whole words (one for u8 joints, two for u16): one load per word.
    if (sp_codec_influences(codec) == 4u) {
        if (codec.packing.y == 1u) {
            uint word = SP_TUPLE_LUT_WORD(tuple_index);
            return uvec4(word & 0xffu, (word >> 8) & 0xffu, (word >> 16) & 0xffu, word >> 24);
        }
        uint low = SP_TUPLE_LUT_WORD(2u * tuple_index), high = SP_TUPLE_LUT_WORD(2u * tuple_index + 1u);
        return uvec4(low & 0xffffu, low >> 16, high & 0xffffu, high >> 16);
    }
    uvec4 joints = uvec4(0u);
    for (uint slot = 0u; slot < sp_codec_influences(codec); ++slot) joints[slot] = sp_lut_joint(codec, tuple_index, slot);
    return joints;
}
#endif

// ---- meshlets (native/include/skinpack.h, "Meshlets") ------------------------------------

#ifdef SP_MESHLET_WORD
struct SpMeshlet {
    uint vertex_offset, triangle_offset, joint_offset, tuple_offset;
    uint vertex_count, triangle_count, joint_count, tuple_count;
    vec4 sphere;      // bind-pose bounding sphere: center, radius
    vec3 cone_apex;
    vec4 cone;        // axis, cutoff (1: too wide to cull)
};

SpMeshlet sp_load_meshlet(uint meshlet_index)
{
    uint base = meshlet_index * SP_MESHLET_WORDS;
    SpMeshlet m;
    m.vertex_offset = SP_MESHLET_WORD(base + SP_MESHLET_WORD_VERTEX_OFFSET);
    m.triangle_offset = SP_MESHLET_WORD(base + SP_MESHLET_WORD_TRIANGLE_OFFSET);
    m.joint_offset = SP_MESHLET_WORD(base + SP_MESHLET_WORD_JOINT_OFFSET);
    m.tuple_offset = SP_MESHLET_WORD(base + SP_MESHLET_WORD_TUPLE_OFFSET);
    uint counts = SP_MESHLET_WORD(base + SP_MESHLET_WORD_COUNTS);
    uint palette = SP_MESHLET_WORD(base + SP_MESHLET_WORD_PALETTE);
    m.vertex_count = counts & 0xffffu;
    m.triangle_count = counts >> 16;
    m.joint_count = palette & 0xffffu;
    m.tuple_count = palette >> 16;
    for (uint i = 0u; i < 4u; ++i) m.sphere[i] = uintBitsToFloat(SP_MESHLET_WORD(base + SP_MESHLET_WORD_CENTER + i));
    for (uint i = 0u; i < 3u; ++i) m.cone_apex[i] = uintBitsToFloat(SP_MESHLET_WORD(base + SP_MESHLET_WORD_CONE_APEX + i));
    for (uint i = 0u; i < 4u; ++i) m.cone[i] = uintBitsToFloat(SP_MESHLET_WORD(base + SP_MESHLET_WORD_CONE_AXIS + i));
    return m;
}
#endif

#ifdef SP_MESHLET_DATA_WORD
// Word offsets of the five sp_meshlet_buffers arrays inside the meshlet data buffer.
struct SpMeshletArrays {
    uint vertices, vertex_tuples, triangles, joints, tuples;
};

uint sp_data_u8(uint array_word, uint index)
{
    return bitfieldExtract(SP_MESHLET_DATA_WORD(array_word + (index >> 2)), int((index & 3u) * 8u), 8);
}

uint sp_data_u16(uint array_word, uint index)
{
    return bitfieldExtract(SP_MESHLET_DATA_WORD(array_word + (index >> 1)), int((index & 1u) * 16u), 16);
}

// Source (global) vertex index of meshlet vertex i.
uint sp_meshlet_vertex(SpMeshletArrays arrays, SpMeshlet m, uint i)
{
    return SP_MESHLET_DATA_WORD(arrays.vertices + m.vertex_offset + i);
}

uvec3 sp_meshlet_triangle(SpMeshletArrays arrays, SpMeshlet m, uint t)
{
    uint first = 3u * (m.triangle_offset + t);
    return uvec3(sp_data_u8(arrays.triangles, first), sp_data_u8(arrays.triangles, first + 1u),
                 sp_data_u8(arrays.triangles, first + 2u));
}

// Joints of meshlet vertex i: local tuple -> palette indices -> joints.
uvec4 sp_meshlet_joints(SpMeshletArrays arrays, SpMeshlet m, uint i, uint influences)
{
    uint local_tuple = sp_data_u8(arrays.vertex_tuples, m.vertex_offset + i);
    uvec4 joints = uvec4(0u);
    for (uint slot = 0u; slot < influences; ++slot) {
        uint palette_index = sp_data_u8(arrays.tuples, influences * (m.tuple_offset + local_tuple) + slot);
        joints[slot] = sp_data_u16(arrays.joints, m.joint_offset + palette_index);
    }
    return joints;
}
#endif

#endif // SKINPACK_DECODE_GLSL
