// gpu.js - the GPU decode path: a GLSL ES 3.00 port of the narrow (32-bit) decoder of
// shaders/skinpack_decode.glsl, its uniforms, the tuple table as an RGBA16UI texture, and the
// patch of three.js's skinning chunks. WebGL2 has no uaddCarry/umulExtended/bitfieldExtract
// (GLSL ES 3.10), so only the 32-bit GPU profile decodes here; wider codecs decode on the CPU.

import { ShaderChunk } from 'three';

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

/** Uniform values of one codec (codec from decode.js codecFromExtension). */
export function codecUniformValues(codec, lutWidth) {
  const config = [codec.methodId, codec.influences, codec.weightBits, codec.tupleBits];
  const params = [codec.n >>> 0, Number(codec.scale) >>> 0, codec.maxCodeNumber >>> 0, lutWidth];
  const bits = [0, 0, 0, 0], axes = [0, 0, 0, 0], factors = [0, 0, 0, 0];
  codec.componentBits.forEach((b, i) => { bits[i] = b; });
  if (codec.method === 'any') codec.axisNumbers.forEach((q, a) => { axes[a] = q; factors[a] = (a + 2) * (q - 1); });
  return { config, params, bits, axes, factors };
}

/** The tuple table as RGBA16UI texels (one entry a texel, rowWidth entries a row). */
export function tupleTexels(lut, influences, rowWidth = TUPLE_TEXTURE_WIDTH) {
  const entries = lut.length / influences;
  const width = Math.min(entries, rowWidth), height = Math.ceil(entries / width);
  const texels = new Uint16Array(width * height * 4);
  for (let e = 0; e < entries; ++e)
    for (let s = 0; s < influences; ++s) texels[e * 4 + s] = lut[e * influences + s];
  return { texels, width, height };
}

// Uniform block and decoder. Method ids are SP_METHOD_* (decode.js METHODS order).
export const DECODE_GLSL = /* glsl */ `
uniform highp usampler2D skinpackTuples;
uniform highp uvec4 skinpackConfig;  // method, K, weight bits, tuple bits
uniform highp uvec4 skinpackParams;  // n (m or N), grid s, largest code, tuple texture width
uniform highp uvec4 skinpackBits;    // fixed/cube/pot: bits of each stored weight, code order
uniform highp uvec4 skinpackAxes;    // any: q2, q3, q4
uniform highp vec4 skinpackFactors;  // any: i (q_i - 1), the divisor of axis i

// The skinning shaders fix method and K at compile time (one program per codec kind, every
// other decoder compiled out); the read-back test leaves them to the uniforms.
#ifndef SKINPACK_METHOD
#define SKINPACK_METHOD skinpackConfig.x
#define SKINPACK_K skinpackConfig.y
#endif

highp uint skinpackRowBase(highp uint n, highp uint j) {
  return (j * (4u * n + 2u - 3u * j) + 1u) / 4u;
}
highp uint skinpackLayerBase(highp uint n, highp uint k) {
  return (3u * n * k * (n + 3u - 2u * k) + k * (4u * k * k + 6u - 9u * k) + 2u) / 9u;
}
highp uint skinpackBase(bool layer, highp uint n, highp uint x) {
  return layer ? skinpackLayerBase(n, x) : skinpackRowBase(n, x);
}
// Largest x in [0, last] with base(x) <= code: gallop from the float estimate, then bisect
// (sp_oss_search32).
highp uint skinpackSearch(bool layer, highp uint n, highp uint last, highp float estimate, highp uint code) {
  highp uint x = estimate >= 0.0 ? uint(min(estimate, float(last))) : 0u;
  x = min(x, last);
  highp uint low, high;
  if (skinpackBase(layer, n, x) <= code) {
    low = x; high = last + 1u;
    for (highp uint step = 1u; step <= last - low; step <<= 1) {
      highp uint probe = low + step;
      if (skinpackBase(layer, n, probe) > code) { high = probe; break; }
      low = probe;
    }
  } else {
    high = x; low = 0u;
    for (highp uint step = 1u; step < high; step <<= 1) {
      highp uint probe = high - step;
      if (skinpackBase(layer, n, probe) <= code) { low = probe; break; }
      high = probe;
    }
  }
  while (high - low > 1u) {
    highp uint middle = low + (high - low) / 2u;
    if (skinpackBase(layer, n, middle) <= code) low = middle; else high = middle;
  }
  return low;
}
highp float skinpackRowEstimate(highp float n, highp float countMinusRest, highp float triangleRemainder) {
  return (2.0 * n + 1.0 - sqrt(12.0 * countMinusRest + 4.0 * triangleRemainder)) / 3.0;
}
highp float skinpackLayerEstimate(highp float n, highp float countMinusCode) {
  highp float v = 72.0 * countMinusCode + 39.0;
  highp float c = pow(v - 1.0 + sqrt(v) * sqrt(v - 2.0), 1.0 / 3.0);
  return (2.0 * n + 3.0 - (c + 1.0 / c)) / 4.0;
}
highp uint skinpackLowBits(highp uint value, highp uint bits) {
  return bits >= 32u ? value : value & ((1u << bits) - 1u);
}
// Exact integers q1..q4 (any: x2..x4 in slots 2..4) and the float weights of one code.
highp vec4 skinpackDecodeWeights(highp uint code, out highp uvec4 q) {
  highp uint method = SKINPACK_METHOD, k = SKINPACK_K;
  q = uvec4(0u);
  if (k == 1u) { q.x = 1u; return vec4(1.0, 0.0, 0.0, 0.0); }
  if (method == 3u) { // any
    highp vec4 w = vec4(0.0);
    highp uint rest = code;
    for (highp uint axis = 0u; axis + 1u < k; ++axis) {
      highp uint samples = skinpackAxes[axis];
      q[axis + 1u] = rest % samples;
      rest /= samples;
      w[axis + 1u] = float(q[axis + 1u]) / skinpackFactors[axis];
    }
    w.x = 1.0 - (w.y + w.z + w.w);
    return w;
  }
  highp uint scale = skinpackParams.y;
  if (method == 4u) { // oss
    highp uint n = skinpackParams.x;
    highp uint layer = 0u, row = 0u, rest = code, bottom = n;
    if (k == 4u) {
      highp float estimate = skinpackLayerEstimate(float(n), float(skinpackParams.z - code) + 1.0);
      layer = skinpackSearch(true, n, (n + 1u) / 2u - 1u, estimate, code);
      rest -= skinpackLayerBase(n, layer);
      bottom = n - 2u * layer;
    }
    if (k >= 3u) {
      highp uint numerator = bottom * bottom + bottom + 1u;
      highp float estimate = skinpackRowEstimate(float(bottom), float(numerator / 3u - rest), float(numerator % 3u));
      row = skinpackSearch(false, bottom, (2u * bottom + 1u) / 3u - 1u, estimate, rest);
      rest -= skinpackRowBase(bottom, row);
    }
    q.w = k == 4u ? layer : 0u;
    q.z = k >= 3u ? row + layer : 0u;
    q.y = rest + row + layer;
    q.x = scale - q.y - q.z - q.w;
    return vec4(q) / float(scale); // division: bit-identical to the C decoder's double q * (1/s) on SwiftShader
  }
  highp uint first = method == 0u ? 0u : 1u; // fixed stores q1 too
  highp uint shift = 0u;
  for (highp uint slot = first; slot < k; ++slot) {
    highp uint width = skinpackBits[slot - first];
    q[slot] = skinpackLowBits(code >> shift, width);
    shift += width;
  }
  if (first == 1u) q.x = scale - (q.y + q.z + q.w);
  return vec4(q) / float(scale);
}
// One packed vertex word -> joints (zero-weight slots: joint 0, as skinpack decompress) and weights.
void skinpackDecode(highp uint word, out highp uvec4 joints, out highp vec4 weights, out highp uvec4 q) {
  highp uint weightBits = skinpackConfig.z;
  highp uint code = skinpackLowBits(word, weightBits);
  highp uint tuple = weightBits >= 32u ? 0u : word >> weightBits;
  weights = skinpackDecodeWeights(code, q);
  highp uint width = skinpackParams.w;
  joints = texelFetch(skinpackTuples, ivec2(int(tuple % width), int(tuple / width)), 0);
  for (int s = 0; s < 4; ++s) if (!(weights[s] > 0.0)) joints[s] = 0u;
}
`;

// three's skinning chunks with the attributes replaced by the decoded values.
function renamed(chunk) {
  return chunk.replace(/\bskinIndex\b/g, 'skinpackIndex').replace(/\bskinWeight\b/g, 'skinpackWeight');
}

/** The program variant of a codec: method and K are compile-time constants of the shader. */
export function codecProgramKey(codec) {
  return `skinpack-gpu-${codec.methodId}-${codec.influences}`;
}

/** Patches a three.js shader (onBeforeCompile's argument) to skin from the packed word. */
export function patchSkinningShader(shader, uniforms, codec) {
  Object.assign(shader.uniforms, uniforms);
  const constants = `#define SKINPACK_METHOD ${codec.methodId}u\n#define SKINPACK_K ${codec.influences}u\n`;
  shader.vertexShader = shader.vertexShader
    .replace('#include <skinning_pars_vertex>',
             `#include <skinning_pars_vertex>\n#ifdef USE_SKINNING\nin highp uint skinpackWord;\n${constants}${DECODE_GLSL}\n#endif`)
    .replace('#include <skinbase_vertex>',
             `#ifdef USE_SKINNING\nhighp uvec4 skinpackJoints; highp vec4 skinpackWeight; highp uvec4 skinpackQ;\n` +
             `skinpackDecode(skinpackWord, skinpackJoints, skinpackWeight, skinpackQ);\n` +
             `vec4 skinpackIndex = vec4(skinpackJoints);\n#endif\n${renamed(ShaderChunk.skinbase_vertex)}`)
    .replace('#include <skinnormal_vertex>', renamed(ShaderChunk.skinnormal_vertex))
    .replace('#include <skinning_vertex>', renamed(ShaderChunk.skinning_vertex));
  if (!shader.vertexShader.includes('skinpackDecode(skinpackWord'))
    throw new Error('SkinpackGLTFPlugin: the material\'s vertex shader has no <skinbase_vertex> chunk to patch');
}
