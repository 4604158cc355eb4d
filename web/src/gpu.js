// gpu.js - the GPU decode path: a GLSL ES 3.00 port of the narrow (32-bit) decoder of
// shaders/skinpack_decode.glsl specialised per codec (#define constants), the tuple table as an
// RGBA16UI texture, and the patch of three.js's skinning chunks. WebGL2 has no uaddCarry,
// umulExtended or bitfieldExtract (GLSL ES 3.10), so only the 32-bit GPU profile decodes here;
// wider codecs decode on the CPU.

import { ShaderChunk, Vector4 } from 'three';

// SP_OSS_NARROW_MAX_CODE_K4 / _K3 of shaders/skinpack_gpu_layout.h: up to these largest codes
// every intermediate of the OSS closed forms stays below 2^32.
export const OSS_NARROW_MAX_CODE_K4 = 477218587;
export const OSS_NARROW_MAX_CODE_K3 = 1073741822;
export const TUPLE_TEXTURE_WIDTH = 2048;

/**
 * Whether the 32-bit shader decodes this codec exactly (the GPU profile): one word a vertex and
 * the limits of SP_GPU_CODEC_IS_NARROW. Returns null if so, else the reason.
 */
export function gpuProfileRefusal(codec) {
  if (codec.wordsPerVertex !== 1) return `${codec.tupleBits + codec.weightBits} bits a vertex need two words (GPU profile: 32)`;
  if (codec.method === 'oss' && codec.influences >= 3) {
    const limit = codec.influences === 4 ? OSS_NARROW_MAX_CODE_K4 : OSS_NARROW_MAX_CODE_K3;
    if (codec.maxCodeNumber > limit) return `oss K = ${codec.influences} codes above ${limit} overflow 32-bit math`;
  }
  if (codec.scale >= 2n ** 32n) return 'grid denominator over 32 bits';
  if (codec.axisSamples.some((q) => q >= 2n ** 32n)) return 'any axis sample counts over 32 bits';
  return null;
}

/** The tuple table as RGBA16UI texels (one entry a texel, rowWidth entries a row). rowWidth is
 *  a power of two: the shader addresses entry t at (t & (rowWidth - 1), t >> log2(rowWidth)). */
export function tupleTexels(lut, influences, rowWidth = TUPLE_TEXTURE_WIDTH) {
  rowBitsOf(rowWidth);
  const entries = lut.length / influences;
  const width = Math.min(entries, rowWidth), height = Math.ceil(entries / width);
  const texels = new Uint16Array(width * height * 4);
  for (let e = 0; e < entries; ++e)
    for (let s = 0; s < influences; ++s) texels[e * 4 + s] = lut[e * influences + s];
  return { texels, width, height };
}

function rowBitsOf(rowWidth) {
  const bits = Math.log2(rowWidth);
  if (!Number.isInteger(bits) || bits < 0 || bits > 15) throw new Error(`tuple texture rows of ${rowWidth} entries: not a power of two up to 2^15`);
  return bits;
}

// GLSL literals: unsigned integers and binary32 values (the nearest float, as a Float32Array
// uniform would hold it; every value written is an integer or a multiple of 1/4).
const uintLiteral = (value) => `${BigInt(value)}u`;
function floatLiteral(value) {
  const text = String(Math.fround(value));
  return /[.e]/.test(text) ? text : `${text}.0`;
}

// Grid methods: q_slot = (code >> shift) & mask for each stored slot (Fixed stores q1 too).
function gridUnpackMacro(codec) {
  const first = codec.method === 'fixed' ? 0 : 1;
  let shift = 0;
  // componentBits has one entry a stored slot (first..K-1), zeros after (sp_codec.component_bits)
  const statements = codec.componentBits.slice(0, codec.influences - first).map((bits, c) => {
    const mask = bits >= 32 ? 0xffffffff : 2 ** bits - 1;
    const statement = `q[${first + c}] = (code >> ${shift}u) & ${uintLiteral(mask)};`;
    shift += bits;
    return statement;
  });
  return statements.join(' ');
}

/**
 * The codec as GLSL #define constants: every parameter the decoder reads but the weights'
 * divisors is fixed at compile time, so the shader compiler folds the closed forms' constant
 * parts and the preprocessor drops the other methods' code.
 * @param {object} codec  decode.js codecFromExtension, inside the GPU profile (gpuProfileRefusal null)
 * @param {number} rowWidth  tuple texture row length, a power of two
 */
export function codecDefines(codec, rowWidth = TUPLE_TEXTURE_WIDTH) {
  const k = codec.influences, rowBits = rowBitsOf(rowWidth);
  const defines = {
    METHOD: codec.methodId, K: k, WEIGHT_BITS: codec.weightBits, // plain integers: the preprocessor tests them
    CODE_MASK: uintLiteral(codec.weightBits >= 32 ? 0xffffffff : 2 ** codec.weightBits - 1),
    ROW_BITS: uintLiteral(rowBits), ROW_MASK: uintLiteral(rowWidth - 1), SCALE: uintLiteral(codec.scale),
  };
  if (k > 1 && codec.method === 'oss') {
    defines.N = uintLiteral(codec.n);
    if (k === 4) {
      // The layer estimate's x(code) = 144 (max code - code) + x(max code) (sp_oss_layer_narrow),
      // x(max code) = 8 M^3 + 12 M^2 - 106 - 144 max code with M = N + 1, a small exact integer.
      const m = BigInt(codec.n) + 1n;
      defines.MAX_CODE = uintLiteral(codec.maxCode);
      defines.LAST_LAYER = uintLiteral((codec.n + 1 >> 1) - 1);
      defines.LAYER_TOP = floatLiteral(Number(8n * m ** 3n + 12n * m * m - 106n - 144n * codec.maxCode));
      defines.LAYER_APEX = floatLiteral((2 * codec.n + 3) / 4);
    }

  }
  if (k > 1 && codec.method === 'any') codec.axisNumbers.forEach((q, a) => { defines[`AXIS${a + 2}`] = uintLiteral(q); });
  if (k > 1 && ['fixed', 'cube', 'pot'].includes(codec.method)) defines['UNPACK_GRID(code, q)'] = gridUnpackMacro(codec);
  return Object.entries(defines).map(([name, value]) => `#define SKINPACK_${name} ${value}\n`).join('');
}

// The decoder (GLSL ES 3.00, after codecDefines). Method ids are SP_METHOD_* (decode.js METHODS
// order). The files were validated on load (decodeSkin), so the shader only decodes.
const DECODE_BODY = /* glsl */ `
uniform highp usampler2D skinpackTuples;
// Divisors of the weights, a uniform so that the division stays one: a compiler may turn a
// division by a constant into a multiplication by its reciprocal, which rounds differently.
uniform highp vec4 skinpackDivisors; // grid: s in x; any: i (q_i - 1) in y, z, w

#if SKINPACK_METHOD == 4 && SKINPACK_K >= 3
// Row j of a triangle with b bottom samples starts at sb(j) = floor((j (4b + 2 - 3j) + 1) / 4).
highp uint skinpackRowBase(highp uint b, highp uint j) {
  return (j * (4u * b + 2u - 3u * j) + 1u) >> 2;
}
// The largest row j with sb(j) <= rest, and sb(j). The estimate is codec_oss_simd.h's
// row_estimate: the mirrored square root for rest + 7/8, (2b + 1 - sqrt(4 (b^2 + b + 1 -
// 3 rest) - 10.5)) / 3 from an exact integer difference. rest + 7/8 lies strictly between the
// unfloored form at j and j + 1, so in exact arithmetic the estimate is in (j, j + 1); float
// error is far below one row (the root is below 2^17 and GLSL ES's highp sqrt is a few ulp), so
// its floor is j - 1, j or j + 1 and one comparison each way makes it exact. No loops or
// fallback branches: on SwiftShader they cost more than the estimate, even untaken
// (docs/benchmarks-web.md); tests/web/gpu_decode.test.mjs checks the bound. For a valid rest (files are validated on load)
// sb(last + 1) = S(b) > rest, so the estimate's largest value, last + 1, comes down.
highp uint skinpackRow(highp uint b, highp uint rest, out highp uint base) {
  highp float root = sqrt(4.0 * float(b * b + b + 1u - 3u * rest) - 10.5);
  highp float estimate = (float(2u * b + 1u) - root) * (1.0 / 3.0);
  highp uint row = estimate > 0.0 ? uint(estimate) : 0u; // at most last + 1; NaN lands on 0
  row -= uint(skinpackRowBase(b, row) > rest);           // sb(0) = 0 <= rest
  row += uint(skinpackRowBase(b, row + 1u) <= rest);
  base = skinpackRowBase(b, row);
  return row;
}
#endif

#if SKINPACK_METHOD == 4 && SKINPACK_K == 4
// 9 u(k) + (its remainder): u(k) <= code iff this <= 9 code + 8, which stays below 2^32 in the
// GPU profile (largest code <= (2^32 - 9) / 9), so only the layer's base needs a division.
highp uint skinpackLayerNumerator(highp uint k) {
  return 3u * SKINPACK_N * k * (SKINPACK_N + 3u - 2u * k) + k * (4u * k * k + 6u - 9u * k) + 2u;
}
// floor(x / 9) for any 32-bit x without an integer division (a CPU has no vector integer
// division: SwiftShader divides lane by lane): a float quotient within about 80 of the result, then the exact
// remainder's correction, r = x - 9 g (|r| < 2^10, exact in float; (r + 1/2) / 9 is at least
// 1/18 from an integer, far more than the product's rounding).
highp uint skinpackDivideBy9(highp uint x) {
  highp uint guess = uint(float(x) * (1.0 / 9.0));
  highp float remainder = float(int(x - 9u * guess));
  return uint(int(guess) + int(floor((remainder + 0.5) * (1.0 / 9.0))));
}
// The largest layer k with u(k) <= code, and u(k): sp_oss_layer_narrow's one cube root
// (t = c + 1/c, c = cbrt(x), x = 144 (max code - code) + x(max code), for code + 17/18, which
// lies strictly inside its layer, codec_oss_simd.h), no square roots. Float error (c < 2^13, a
// few ulp through pow and the reciprocal) moves the floor by at most one layer, so one
// comparison each way makes it exact, as for the row.
highp uint skinpackLayer(highp uint code, out highp uint base) {
  highp float c = pow(144.0 * float(SKINPACK_MAX_CODE - code) + SKINPACK_LAYER_TOP, 1.0 / 3.0);
  highp float estimate = SKINPACK_LAYER_APEX - 0.25 * (c + 1.0 / c);
  highp uint layer = estimate > 0.0 ? min(uint(estimate), SKINPACK_LAST_LAYER) : 0u; // NaN lands on 0
  highp uint bound = 9u * code + 8u;
  layer -= uint(skinpackLayerNumerator(layer) > bound); // 9 u(0) + 2 = 2 <= bound
  layer += uint(layer < SKINPACK_LAST_LAYER) & uint(skinpackLayerNumerator(layer + 1u) <= bound);
  base = skinpackDivideBy9(skinpackLayerNumerator(layer));
  return layer;
}
#endif

// Exact integers q1..q4 (Any: x2..x4 in slots 2..4) and the float weights of one code.
highp vec4 skinpackDecodeWeights(highp uint code, out highp uvec4 q) {
  q = uvec4(0u);
#if SKINPACK_K == 1
  q.x = SKINPACK_SCALE;
  return vec4(1.0, 0.0, 0.0, 0.0);
#elif SKINPACK_METHOD == 3 // any: mixed radix, w_i = x_i / (i (q_i - 1)), w1 = 1 - the rest
  highp vec4 w = vec4(0.0);
  q.y = code % SKINPACK_AXIS2;
  w.y = float(q.y) / skinpackDivisors.y;
#if SKINPACK_K >= 3
  code /= SKINPACK_AXIS2;
  q.z = code % SKINPACK_AXIS3;
  w.z = float(q.z) / skinpackDivisors.z;
#endif
#if SKINPACK_K == 4
  code /= SKINPACK_AXIS3;
  q.w = code % SKINPACK_AXIS4;
  w.w = float(q.w) / skinpackDivisors.w;
#endif
  w.x = 1.0 - (w.y + w.z + w.w);
  return w;
#else
#if SKINPACK_METHOD == 4 // oss: layer k, row j, index i; q4 = k, q3 = j + k, q2 = i + j + k
  highp uint layer = 0u, row = 0u, rest = code, base;
#if SKINPACK_K == 4
  layer = skinpackLayer(code, base);
  rest -= base;
#endif
#if SKINPACK_K >= 3
  row = skinpackRow(SKINPACK_N - 2u * layer, rest, base);
  rest -= base;
#endif
  q.w = layer;
#if SKINPACK_K >= 3
  q.z = row + layer;
#endif
  q.y = rest + row + layer;
  q.x = SKINPACK_SCALE - q.y - q.z - q.w;
#else // fixed stores q1..qK, cube and pot q2..qK
  SKINPACK_UNPACK_GRID(code, q)
#if SKINPACK_METHOD != 0
  q.x = SKINPACK_SCALE - (q.y + q.z + q.w);
#endif
#endif
  return vec4(q) / skinpackDivisors.x; // a division: bit-identical to the C decoder's double q * (1/s) on SwiftShader
#endif
}

// One packed vertex word -> joints (zero-weight slots: joint 0, as skinpack decompress) and weights.
void skinpackDecode(highp uint word, out highp uvec4 joints, out highp vec4 weights, out highp uvec4 q) {
  highp uint code = word & SKINPACK_CODE_MASK;
#if SKINPACK_WEIGHT_BITS < 32
  highp uint tuple = word >> SKINPACK_WEIGHT_BITS;
#else
  highp uint tuple = 0u;
#endif
  weights = skinpackDecodeWeights(code, q);
  joints = texelFetch(skinpackTuples, ivec2(int(tuple & SKINPACK_ROW_MASK), int(tuple >> SKINPACK_ROW_BITS)), 0);
  joints *= uvec4(greaterThan(weights, vec4(0.0)));
}
`;

/** The decoder of one codec (GLSL ES 3.00): skinpackDecode(word, out joints, out weights, out q). */
export function decodeGlsl(codec, rowWidth = TUPLE_TEXTURE_WIDTH) {
  return codecDefines(codec, rowWidth) + DECODE_BODY;
}

/** skinpackDivisors of a codec: s (grid methods) or i (q_i - 1) (any, binary64 like the CPU decoder, then binary32). */
export function codecDivisors(codec) {
  // Any's divisors i (q_i - 1), i = 2..K, in binary64 as the C decoder computes them (exact: q_i < 2^32)
  if (codec.method === 'any') return [1, ...codec.axisNumbers.map((q, a) => (a + 2) * (q - 1)), 0, 0].slice(0, 4);
  return [Number(codec.scale), 0, 0, 0];
}

/** The uniforms of the GPU skin (three.js form): the tuple texture and the weights' divisors. */
export function gpuSkinUniforms(codec, tupleTexture) {
  return { skinpackTuples: { value: tupleTexture }, skinpackDivisors: { value: new Vector4(...codecDivisors(codec)) } };
}

// three's skinning chunks with the attributes replaced by the decoded values.
function renamed(chunk) {
  return chunk.replace(/\bskinIndex\b/g, 'skinpackIndex').replace(/\bskinWeight\b/g, 'skinpackWeight');
}

/** The program variant of a codec: three.js shares a program between materials with one key,
 *  and every codec parameter is a constant of the program. */
export function codecProgramKey(codec) {
  return `skinpack-gpu;${codecDefines(codec).replace(/#define SKINPACK_/g, '').replace(/\n/g, ';')}`;
}

/** Patches a three.js shader (onBeforeCompile's argument) to skin from the packed word: one
 *  decode a vertex, in skinbase_vertex; skinnormal_vertex and skinning_vertex use its result. */
export function patchSkinningShader(shader, uniforms, codec) {
  Object.assign(shader.uniforms, uniforms);
  shader.vertexShader = shader.vertexShader
    .replace('#include <skinning_pars_vertex>',
             `#include <skinning_pars_vertex>\n#ifdef USE_SKINNING\nin highp uint skinpackWord;\n${decodeGlsl(codec)}\n#endif`)
    .replace('#include <skinbase_vertex>',
             `#ifdef USE_SKINNING\nhighp uvec4 skinpackJoints; highp vec4 skinpackWeight; highp uvec4 skinpackQ;\n` +
             `skinpackDecode(skinpackWord, skinpackJoints, skinpackWeight, skinpackQ);\n` +
             `vec4 skinpackIndex = vec4(skinpackJoints);\n#endif\n${renamed(ShaderChunk.skinbase_vertex)}`)
    .replace('#include <skinnormal_vertex>', renamed(ShaderChunk.skinnormal_vertex))
    .replace('#include <skinning_vertex>', renamed(ShaderChunk.skinning_vertex));
  if (!shader.vertexShader.includes('skinpackDecode(skinpackWord'))
    throw new Error('SkinpackGLTFPlugin: the material\'s vertex shader has no <skinbase_vertex> chunk to patch');
}
