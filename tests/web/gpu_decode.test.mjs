// gpu_decode.test.mjs - the margin of the WebGL2 OSS decoder's float estimates (web/src/gpu.js),
// in node. The shader settles each estimate with one comparison each way and no search, so it
// is exact only if the floored float estimate is within one of the true layer and row. This
// emulates the shader's binary32 arithmetic (Math.fround after every operation) with the roots
// moved by ROOT_ULPS ulp either way (more than GLSL ES 3.00 allows highp pow and sqrt to be off,
// so a GPU that rounds differently from SwiftShader stays exact; the layers pass with 1000 ulp,
// the rows with 256) and checks every layer's and every row's first and last
// code: all of them for every K = 4 codec of the GPU profile, rows for sampled K = 3 codecs;
// and the division by 9 without integer division (skinpackDivideBy9).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { codecFromExtension } from '../../web/src/decode.js';

// The OSS closed forms of the spec (docs/extension/README.md), in BigInt: the test's oracle for
// where each row and layer starts. The runtime itself decodes through the library (wasm.js).
function ossRowBase(n, j) {
  return (4n * j * n + 2n * j + 1n - 3n * j * j) / 4n;
}
function ossLayerBase(n, k) {
  return (3n * n * k * (n - 2n * k + 3n) + k * (4n * k * k - 9n * k + 6n) + 2n) / 9n;
}
function ossCodeCount(n, k) {
  if (k === 1) return 1n;
  if (k === 2) return n;
  return k === 3 ? (n * n + n + 1n) / 3n : ossLayerBase(n, (n + 1n) / 2n);
}
import { codecDefines, OSS_NARROW_MAX_CODE_K3, OSS_NARROW_MAX_CODE_K4 } from '../../web/src/gpu.js';

const ROOT_ULPS = 64;
const f = Math.fround;
const F32 = new Float32Array(1), U32 = new Uint32Array(F32.buffer);

function ulpShift(value, ulps) { // value (a positive binary32) moved by ulps units in the last place
  F32[0] = value;
  U32[0] += ulps;
  return F32[0];
}

function floorEstimate(estimate, last) { // the shader's estimate > 0.0 ? min(uint(estimate), last) : 0u
  return estimate > 0 ? Math.min(Math.floor(estimate), last) : 0;
}

// Largest N whose K-influence code count stays inside the GPU profile.
function largestNarrowN(k, limit) {
  let n = 2;
  while (Number(ossCodeCount(BigInt(n + 1), k)) - 1 <= limit) ++n;
  return n;
}

function ossCodec(k, n) {
  const bits = Number(ossCodeCount(BigInt(n), k) - 1n).toString(2).length;
  return codecFromExtension({ vertices: 0, tupleTable: 0, influences: k, jointCount: 1, method: 'oss', n, weightBits: bits, tupleBits: 0 });
}

function defineValue(defines, name) {
  return Number(new RegExp(`#define SKINPACK_${name} ([0-9.e+-]+)u?\\n`).exec(defines)[1]);
}

// skinpackLayer's estimate for code, the cube root moved by ulps.
function layerEstimate(constants, code, ulps) {
  const x = f(f(144 * f(constants.maxCode - code)) + constants.top);
  const c = ulpShift(f(Math.cbrt(x)), ulps);
  return floorEstimate(f(constants.apex - f(0.25 * f(c + f(1 / c)))), constants.last);
}

// skinpackRow's estimate, the square root moved by ulps.
function rowEstimate(b, rest, ulps) {
  const root = ulpShift(f(Math.sqrt(f(f(4 * f(b * b + b + 1 - 3 * rest)) - 10.5))), ulps);
  return floorEstimate(f(f(f(2 * b + 1) - root) * f(1 / 3)), Infinity);
}

// Every row's first and last in-triangle index for b bottom samples; returns the worst miss.
function checkRows(b) {
  const rows = Math.floor((2 * b + 1) / 3), big = BigInt(b);
  let worst = 0;
  for (let j = 0; j < rows; ++j) {
    const first = Number(ossRowBase(big, BigInt(j))), end = Number(ossRowBase(big, BigInt(j + 1)));
    for (const rest of [first, end - 1])
      for (const ulps of [-ROOT_ULPS, 0, ROOT_ULPS]) worst = Math.max(worst, Math.abs(rowEstimate(b, rest, ulps) - j));
  }
  return worst;
}

test('K = 4 layer estimates are within one layer for every codec of the GPU profile', () => {
  const largest = largestNarrowN(4, OSS_NARROW_MAX_CODE_K4);
  assert.ok(largest > 1000, `largest N ${largest}`);
  let checked = 0, worst = 0;
  for (let n = 3; n <= largest; ++n) {
    const defines = codecDefines(ossCodec(4, n));
    const constants = { maxCode: defineValue(defines, 'MAX_CODE'), top: defineValue(defines, 'LAYER_TOP'),
      apex: defineValue(defines, 'LAYER_APEX'), last: defineValue(defines, 'LAST_LAYER') };
    const big = BigInt(n);
    for (let k = 0; k <= constants.last; ++k) {
      const first = Number(ossLayerBase(big, BigInt(k))), end = Number(ossLayerBase(big, BigInt(k + 1)));
      for (const code of [first, end - 1])
        for (const ulps of [-ROOT_ULPS, 0, ROOT_ULPS]) {
          worst = Math.max(worst, Math.abs(layerEstimate(constants, code, ulps) - k));
          checked++;
        }
    }
  }
  console.log(`# ${checked} layer estimates up to N = ${largest}: worst miss ${worst} layer(s)`);
  assert.ok(worst <= 1, `a layer estimate is ${worst} layers off`);
});

test('row estimates are within one row: every in-layer triangle of K = 4, sampled K = 3 codecs up to the GPU profile limit', () => {
  const largest4 = largestNarrowN(4, OSS_NARROW_MAX_CODE_K4), largest3 = largestNarrowN(3, OSS_NARROW_MAX_CODE_K3);
  let worst = 0;
  for (let b = 1; b <= largest4; ++b) worst = Math.max(worst, checkRows(b));
  const sampled = [largest3, largest3 - 1];
  for (let n = largest4 + 1; n < largest3; n += Math.floor((largest3 - largest4) / 40)) sampled.push(n);
  for (const n of sampled) worst = Math.max(worst, checkRows(n));
  console.log(`# rows of every b <= ${largest4} and ${sampled.length} N up to ${largest3}: worst miss ${worst} row(s)`);
  assert.ok(worst <= 1, `a row estimate is ${worst} rows off`);
});

// skinpackDivideBy9 in binary32, the float quotient's guess moved by up to 4 either way (any
// rounding of the conversion and product).
function divideBy9(x, shift) {
  const guess = Math.trunc(f(f(x) * f(1 / 9))) + shift;
  const remainder = x - 9 * guess; // the shader's x - 9u * guess as int: exact, small
  return guess + Math.floor(f(f(remainder + 0.5) * f(1 / 9)));
}

test('the shader\'s division by 9 is exact for every 32-bit value (edges, every residue near 2^32, random)', () => {
  const values = [0, 1, 8, 9, 10, 2 ** 24 - 1, 2 ** 24, 2 ** 24 + 1, 2 ** 31 - 1, 2 ** 31, 2 ** 32 - 1];
  for (let x = 2 ** 32 - 4096; x < 2 ** 32; ++x) values.push(x);
  for (let p = 1; p < 32; ++p) for (let d = -20; d <= 20; ++d) if (2 ** p + d >= 0) values.push(2 ** p + d);
  let seed = 12345;
  for (let i = 0; i < 200000; ++i) { seed = (seed * 1103515245 + 12345) % 2 ** 31; values.push(Math.floor((seed / 2 ** 31) * 2 ** 32)); }
  for (const x of values)
    for (const shift of [-4, 0, 4]) assert.equal(divideBy9(x, shift), Math.floor(x / 9), `x = ${x}, guess ${shift} off`);
});
