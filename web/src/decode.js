// decode.js - CPU decoder of SKINPACK_packed_skin (docs/format.md, docs/extension/README.md).
//
// A port of libskinpack's sp_codec_from_params + sp_decompress_skin: the same checks, the same
// exact integer math and the same float rounding, so the joints and weights are bit-identical
// to `skinpack decompress`. Codecs whose vertex values and closed-form intermediates stay below
// 2^53 run on plain Numbers (every integer is exact there); wider ones (two-word values, 64-bit
// codes) use BigInt, which is slower but exact for every width the format allows.

export const SKINPACK_EXTENSION = 'SKINPACK_packed_skin';
export const METHODS = ['fixed', 'cube', 'pot', 'any', 'oss']; // SP_METHOD_* order
export const MAX_INFLUENCES = 4;
export const MAX_JOINTS = 65535;
export const MAX_WEIGHT_BITS = 64;
export const MAX_TUPLE_BITS = 32;

// Largest code the Number path takes: keeps 12 code (K = 3 row estimate) and 9 u(k) + 9 (K = 4
// layer base) below 2^53.
const NUMBER_MAX_CODE = 2 ** 48;
const TWO_32 = 2 ** 32;

export class SkinpackDecodeError extends Error {
  /** @param {string} message  @param {number} [vertex] vertex (or table entry) the error is at */
  constructor(message, vertex) {
    super(message);
    this.name = 'SkinpackDecodeError';
    this.vertex = vertex;
  }
}

function fail(message, vertex) {
  throw new SkinpackDecodeError(message, vertex);
}

function isInteger(value, low, high) {
  return Number.isInteger(value) && value >= low && value <= high;
}

const TWO_53 = 2n ** 53n, MAX_U64 = 2n ** 64n - 1n;

/**
 * A non-negative integer property that may exceed 2^53 (spec 1.0, "Large integers"): a JSON
 * number up to 2^53, or a string of decimal digits for a value above 2^53 (at most 2^64 - 1).
 */
export function parseLargeInteger(value, field) {
  if (typeof value === 'number') {
    if (!Number.isInteger(value) || value < 0 || value > Number(TWO_53)) fail(`${field} = ${value} must be an integer 0..2^53 (larger values are strings)`);
    return BigInt(value);
  }
  if (typeof value === 'string' && /^[1-9][0-9]*$/.test(value)) {
    const big = BigInt(value);
    if (big > TWO_53 && big <= MAX_U64) return big;
  }
  fail(`${field} = ${JSON.stringify(value)} must be an integer (a decimal string only above 2^53, at most 2^64 - 1)`);
}

/** ceil(log2(count)) for count >= 1 (sp_index_bits); count may be a Number or a BigInt. */
export function indexBits(count) {
  let bits = 0;
  const c = BigInt(count);
  while ((1n << BigInt(bits)) < c) ++bits;
  return bits;
}

function bitWidth(value) { // bits of a BigInt value (0 for 0)
  let bits = 0;
  while (bits < 64 && (value >> BigInt(bits)) !== 0n) ++bits;
  return bits;
}

/**
 * Whether a primitive is in compact mode (its JOINTS_0/WEIGHTS_0 carry no data), from the glTF
 * JSON: the attributes are absent, their accessor has no bufferView, or its bufferView lies in
 * a buffer marked as our data-less fallback (EXT_meshopt_compression style:
 * `buffers[i].extensions.SKINPACK_packed_skin.fallback = true`). Returns null (fallback mode),
 * 'absent', 'no-bufferView' or 'fallback-buffer'.
 */
export function compactLayout(json, primitiveDef) {
  const index = primitiveDef.attributes.JOINTS_0;
  if (index === undefined) return 'absent';
  const accessor = json.accessors[index];
  if (accessor.bufferView === undefined) return 'no-bufferView';
  const view = json.bufferViews[accessor.bufferView];
  const buffer = view && json.buffers[view.buffer];
  return isFallbackBuffer(buffer) ? 'fallback-buffer' : null;
}

/** Bytes of a joint index in JOINTS_n and in the tuple table: 1 up to 256 joints, else 2 (the
 * library's sp_joint_bytes rule; jointCount already checked by codecFromExtension). */
export function jointBytes(jointCount) {
  return jointCount <= 256 ? 1 : 2;
}

/** A buffer without data that only compact primitives' JOINTS_0/WEIGHTS_0 point into. */
export function isFallbackBuffer(buffer) {
  const mark = buffer && buffer.extensions && buffer.extensions[SKINPACK_EXTENSION];
  return !!(mark && mark.fallback === true);
}

// ---- OSS closed forms (BigInt, exact) -------------------------------------------------------

export function ossRowBase(n, j) {
  return (4n * j * n + 2n * j + 1n - 3n * j * j) / 4n;
}

export function ossLayerBase(n, k) {
  return (3n * n * k * (n - 2n * k + 3n) + k * (4n * k * k - 9n * k + 6n) + 2n) / 9n;
}

export function ossCodeCount(n, k) {
  switch (k) {
    case 1: return 1n;
    case 2: return n;
    case 3: return (n * n + n + 1n) / 3n;
    default: return ossLayerBase(n, (n + 1n) / 2n);
  }
}

// ---- codec from the extension's parameters (sp_codec_from_params) ---------------------------

function gridComponentBits(method, slot, m) {
  if (method !== 'pot') return m;
  const i = slot + 1;
  let drop = 0;
  while ((2 << drop) <= i) ++drop;
  return m - drop;
}

function configureGrid(codec, method, k, big) {
  const m = Number(big);
  if (big > 64n || !isInteger(m, method === 'pot' ? 2 : 1, 64)) fail(`"n" = ${big} is not a valid m for ${method}`);
  const first = method === 'fixed' ? 0 : 1;
  let total = 0;
  for (let slot = first; slot < k; ++slot) {
    const bits = gridComponentBits(method, slot, m);
    codec.componentBits.push(bits);
    total += bits;
  }
  if (total > MAX_WEIGHT_BITS) fail(`"n" = ${m} needs ${total} bits for ${k} influences (at most 64)`);
  codec.scale = (1n << BigInt(m)) - 1n;
  codec.maxCode = (1n << BigInt(total)) - 1n;
  codec.maxError = (k - 1) / (k * Number(codec.scale));
}

function configureOss(codec, k, n) {
  if (n < 2n) fail(`"n" = ${n} is not a valid N for oss`);
  const count = ossCodeCount(n, k);
  if (count - 1n >= 1n << 64n) fail(`"n" = ${n} gives codes over 64 bits for ${k} influences`);
  codec.scale = 2n * (n - 1n);
  codec.maxCode = count - 1n;
  codec.maxError = (k - 1) / (k * Number(codec.scale));
}

function configureAny(codec, k, axisSamples) {
  if (!Array.isArray(axisSamples) || axisSamples.length !== k - 1)
    fail(`"axisSamples" must list ${k - 1} sample counts for any with ${k} influences`);
  let count = 1n, w1Error = 0;
  for (let a = 0; a < k - 1; ++a) {
    const q = parseLargeInteger(axisSamples[a], `"axisSamples"[${a}]`);
    if (q < 2n) fail(`"axisSamples"[${a}] = ${q} must be >= 2`);
    count *= q;
    if (count > 1n << 64n) fail('"axisSamples" give codes over 64 bits');
    codec.axisSamples.push(q);
    codec.axisDivisors.push((a + 2) * Number(q - 1n)); // binary64, as the reference computes it
    w1Error += 1 / codec.axisDivisors[a] / 2;
  }
  codec.scale = 0n;
  codec.maxCode = count - 1n;
  codec.maxError = w1Error;
}

/**
 * Validates the extension object of one primitive and returns its codec: everything the
 * decoders need, with BigInt fields (scale, maxCode, axisSamples) and a `number` flag telling
 * whether the Number path is exact for it. Throws SkinpackDecodeError naming the field.
 * @param {object} ext  the primitive's extensions.SKINPACK_packed_skin
 */
export function codecFromExtension(ext) {
  if (!ext || typeof ext !== 'object') fail('extension object missing');
  for (const field of ['vertices', 'tupleTable', 'influences', 'jointCount', 'method', 'n', 'weightBits', 'tupleBits'])
    if (ext[field] === undefined) fail(`"${field}" missing`);
  const k = ext.influences, method = ext.method;
  if (!isInteger(k, 1, MAX_INFLUENCES)) fail(`"influences" = ${k} must be 1..4`);
  if (!isInteger(ext.jointCount, 1, MAX_JOINTS)) fail(`"jointCount" = ${ext.jointCount} must be 1..65535`);
  if (!METHODS.includes(method)) fail(`unknown "method" ${JSON.stringify(method)}`);
  if (!isInteger(ext.weightBits, 0, MAX_WEIGHT_BITS)) fail(`"weightBits" = ${ext.weightBits} must be 0..64`);
  if (!isInteger(ext.tupleBits, 0, MAX_TUPLE_BITS)) fail(`"tupleBits" = ${ext.tupleBits} must be 0..32`);
  const n = parseLargeInteger(ext.n, '"n"');
  const codec = {
    method, methodId: METHODS.indexOf(method), influences: k, jointCount: ext.jointCount,
    n: Number(n), nBig: n, componentBits: [], axisSamples: [], axisDivisors: [], scale: 1n, maxCode: 0n,
    maxError: 0, weightBits: ext.weightBits, tupleBits: ext.tupleBits,
  };
  if (ext.axisSamples !== undefined && (method !== 'any' || k === 1))
    fail(`"axisSamples" must be absent for ${k === 1 ? '1 influence' : method}`);
  if (k === 1) {
    if (n !== 0n) fail(`"n" = ${n} must be 0 for 1 influence`);
  } else if (method === 'any') {
    if (n !== 0n) fail(`"n" = ${n} must be 0 for any`);
    configureAny(codec, k, ext.axisSamples);
  } else if (method === 'oss') {
    configureOss(codec, k, n);
  } else {
    configureGrid(codec, method, k, n);
  }
  const bits = bitWidth(codec.maxCode);
  if (bits !== ext.weightBits) fail(`"weightBits" = ${ext.weightBits} but ${method} with n = ${ext.n} has ${bits}-bit codes`);
  const valueBits = ext.tupleBits + ext.weightBits;
  if (valueBits > 64) fail(`"tupleBits" + "weightBits" = ${valueBits} exceeds 64`);
  codec.wordsPerVertex = valueBits <= 32 ? 1 : 2;
  codec.number = valueBits <= 53 && codec.maxCode <= BigInt(NUMBER_MAX_CODE) && codec.scale < 2n ** 53n;
  codec.scaleNumber = Number(codec.scale);
  codec.maxCodeNumber = Number(codec.maxCode);
  codec.axisNumbers = codec.axisSamples.map(Number);
  let shift = 0; // grid fields: shift, 2^shift and 2^bits for the Number path
  codec.fields = codec.componentBits.map((bits) => {
    const field = { shift, scale: 2 ** shift, range: 2 ** bits, mask: bits >= 32 ? 0xffffffff : 2 ** bits - 1 };
    shift += bits;
    return field;
  });
  codec.code32 = codec.maxCode < 2n ** 32n;
  if (method === 'oss' && k === 4) { // x(max code) of findLayerNumber's estimate: at least 6
    const m = n + 1n;
    codec.layerTop = Number(8n * m ** 3n + 12n * m * m - 106n - 144n * codec.maxCode);
  }
  return codec;
}

// ---- weight decoders, Number path -----------------------------------------------------------

const GRID = new Float64Array(4); // scratch integers of the Number path (exact below 2^53)

function rowBaseNumber(n, j) {
  return Math.floor((4 * j * n + 2 * j + 1 - 3 * j * j) / 4);
}

function layerBaseNumber(n, k) {
  return Math.floor((3 * n * k * (n - 2 * k + 3) + k * (4 * k * k - 9 * k + 6) + 2) / 9);
}

// Largest row j with s_N(j) <= w (oss_find_row): the mirrored square root for w + 7/8, which
// lies strictly inside row j's interval of the unfloored form (codec_oss_simd.h's
// row_estimate), from the exact integer n^2 + n + 1 - 3w; float error moves it by at most a
// row or so, and the loops make it exact whatever the estimate.
function findRowNumber(n, w) {
  const rows = Math.floor((2 * n + 1) / 3);
  const estimate = (2 * n + 1 - Math.sqrt(4 * (n * n + n + 1 - 3 * w) - 10.5)) / 3;
  let j = estimate > 0 ? Math.floor(estimate) : 0; // NaN lands on 0
  if (j >= rows) j = rows - 1;
  while (j + 1 < rows && rowBaseNumber(n, j + 1) <= w) ++j;
  while (j > 0 && rowBaseNumber(n, j) > w) --j;
  return j;
}

// Largest layer k with u(k) <= code (oss_find_layer): one cube root, t = c + 1/c with
// c = cbrt(x), x = 8 M^3 + 12 M^2 - 106 - 144 code (M = N + 1) for code + 17/18, which lies
// strictly inside its layer (native/src/codec_oss.c's find_layer_small): no square root.
// x = 144 (max code - code) + x(max code), the latter a small exact integer (codec.layerTop),
// so the estimate has no cancellation; the loops make it exact.
function findLayerNumber(codec, code) {
  const n = codec.n, layers = Math.floor((n + 1) / 2);
  const c = Math.cbrt(144 * (codec.maxCodeNumber - code) + codec.layerTop);
  const estimate = (2 * n + 3) / 4 - (c + 1 / c) / 4;
  let k = estimate > 0 ? Math.floor(estimate) : 0; // NaN lands on 0
  if (k >= layers) k = layers - 1;
  while (k + 1 < layers && layerBaseNumber(n, k + 1) <= code) ++k;
  while (k > 0 && layerBaseNumber(n, k) > code) --k;
  return k;
}

function ossUnpackNumber(codec, code, q) {
  const n = codec.n, k = codec.influences;
  if (k === 2) {
    q[1] = code;
    q[0] = 2 * (n - 1) - code;
    return;
  }
  let layer = 0, rest = code, bottom = n;
  if (k === 4) {
    layer = findLayerNumber(codec, code);
    rest -= layerBaseNumber(n, layer);
    bottom = n - 2 * layer;
  }
  const row = findRowNumber(bottom, rest);
  const i = rest - rowBaseNumber(bottom, row);
  q[3] = k === 4 ? layer : 0;
  q[2] = row + layer;
  q[1] = i + row + layer;
  q[0] = 2 * (n - 1) - q[1] - q[2] - q[3];
}

function gridUnpackNumber(codec, code, q) {
  let rest = codec.scaleNumber;
  const first = codec.method === 'fixed' ? 0 : 1, fields = codec.fields, code32 = codec.code32;
  for (let i = first, c = 0; i < codec.influences; ++i, ++c) {
    const field = fields[c];
    q[i] = code32 ? ((code >>> field.shift) & field.mask) >>> 0 : Math.floor(code / field.scale) % field.range;
    if (i > 0) rest = rest >= q[i] ? rest - q[i] : 0;
  }
  if (first === 1) q[0] = rest;
}

// Any (spec 1.0, "Exact float result"): binary64 accumulation, binary32 results, w1 >= 0.
function anyDecode(codec, code, weights, offset, big, grid) {
  let rest = 1;
  for (let a = 0; a + 1 < codec.influences; ++a) {
    let x;
    if (big) {
      const q = codec.axisSamples[a];
      x = code % q;
      code /= q;
    } else {
      const q = codec.axisNumbers[a];
      x = code % q;
      code = Math.floor(code / q);
    }
    if (grid) grid[a] = x;
    const w = Number(x) * (1 / codec.axisDivisors[a]);
    weights[offset + a + 1] = w;
    rest -= w;
  }
  weights[offset] = rest;
  return rest >= 0;
}

// Sorted grid point summing to s (decode_valid); writes float(q * (1/s)).
function gridToWeights(q, k, scale, weights, offset, grid) {
  let sum = 0;
  for (let i = 0; i < k; ++i) {
    if (i > 0 && q[i] > q[i - 1]) return false;
    sum += q[i];
  }
  if (sum !== scale) return false;
  if (grid) for (let i = 0; i < k; ++i) grid[i] = q[i];
  const inverse = 1 / scale;
  for (let i = 0; i < k; ++i) weights[offset + i] = q[i] * inverse;
  return true;
}

// ---- weight decoders, BigInt path ------------------------------------------------------------

function findBig(layer, n, count, value) {
  // Exact integer search (the estimate of the Number path is not needed for correctness):
  // bisect the largest x in [0, count) with base(x) <= value.
  let low = 0n, high = count; // base(low) <= value < base(high) (high may be past the end)
  const base = layer ? ossLayerBase : ossRowBase;
  while (high - low > 1n) {
    const middle = (low + high) / 2n;
    if (base(n, middle) <= value) low = middle;
    else high = middle;
  }
  return low;
}

function ossUnpackBig(n, k, code, q) {
  if (k === 2) {
    q[1] = code;
    q[0] = 2n * (n - 1n) - code;
    return;
  }
  let layer = 0n, rest = code, bottom = n;
  if (k === 4) {
    layer = findBig(true, n, (n + 1n) / 2n, code);
    rest -= ossLayerBase(n, layer);
    bottom = n - 2n * layer;
  }
  const row = findBig(false, bottom, (2n * bottom + 1n) / 3n, rest);
  const i = rest - ossRowBase(bottom, row);
  q[3] = k === 4 ? layer : 0n;
  q[2] = row + layer;
  q[1] = i + row + layer;
  q[0] = 2n * (n - 1n) - q[1] - q[2] - q[3];
}

function gridUnpackBig(codec, code, q) {
  let shift = 0n, rest = codec.scale;
  const first = codec.method === 'fixed' ? 0 : 1;
  for (let i = first, c = 0; i < codec.influences; ++i, ++c) {
    const bits = BigInt(codec.componentBits[c]);
    q[i] = (code >> shift) & ((1n << bits) - 1n);
    shift += bits;
    if (i > 0) rest = rest >= q[i] ? rest - q[i] : 0n;
  }
  if (first === 1) q[0] = rest;
}

function gridToWeightsBig(q, k, scale, weights, offset, grid) {
  let sum = 0n;
  for (let i = 0; i < k; ++i) {
    if (i > 0 && q[i] > q[i - 1]) return false;
    sum += q[i];
  }
  if (sum !== scale) return false;
  if (grid) for (let i = 0; i < k; ++i) grid[i] = q[i];
  const inverse = 1 / Number(scale);
  for (let i = 0; i < k; ++i) weights[offset + i] = Number(q[i]) * inverse;
  return true;
}

/**
 * Decodes one weight code (Number for the Number path, else BigInt) into K weights written to
 * weights[offset ...] (a Float32Array rounds them like the C decoder). Returns false for a code
 * no encoder writes: above the code count, off the simplex or unsorted (decode_valid).
 * grid (optional array) receives the exact integers: q1..qK, or x2..xK for Any.
 */
export function decodeWeightCode(codec, code, weights, offset = 0, grid = null) {
  const k = codec.influences;
  const big = typeof code === 'bigint';
  if (big ? code > codec.maxCode : code > codec.maxCodeNumber) return false;
  if (k === 1) {
    weights[offset] = 1;
    return true;
  }
  if (codec.method === 'any') return anyDecode(codec, code, weights, offset, big, grid);
  if (big) {
    const q = [0n, 0n, 0n, 0n];
    if (codec.method === 'oss') ossUnpackBig(codec.nBig, k, code, q);
    else gridUnpackBig(codec, code, q);
    return gridToWeightsBig(q, k, codec.scale, weights, offset, grid);
  }
  const q = GRID;
  q[0] = q[1] = q[2] = q[3] = 0;
  if (codec.method === 'oss') ossUnpackNumber(codec, code, q);
  else gridUnpackNumber(codec, code, q);
  return gridToWeights(q, k, codec.scaleNumber, weights, offset, grid);
}

// ---- whole primitives (sp_decompress_skin) ----------------------------------------------------

function splitValue(codec, words, v) {
  if (codec.wordsPerVertex === 1) return codec.number ? words[v] : BigInt(words[v]);
  const low = words[2 * v], high = words[2 * v + 1];
  if (codec.number) return high * TWO_32 + low;
  return (BigInt(high) << 32n) | BigInt(low);
}

// Writes the joints of vertex v (zero-weight slots keep joint 0); a joint may carry weight once.
function writeJoints(k, lut, tuple, joints, weights, offset, v) {
  for (let s = 0; s < k; ++s) {
    if (!(weights[offset + s] > 0)) continue;
    const joint = lut[tuple * k + s];
    for (let t = 0; t < s; ++t)
      if (joints[offset + t] === joint && weights[offset + t] > 0) fail(`vertex ${v}: joint ${joint} carries weight in two slots`, v);
    joints[offset + s] = joint;
  }
}

// One 32-bit word a vertex: integer operations only.
function decodeWords32(codec, words, lut, lutSize, joints, weights) {
  const k = codec.influences, weightBits = codec.weightBits, valueBits = codec.tupleBits + weightBits;
  const codeMask = weightBits >= 32 ? 0xffffffff : 2 ** weightBits - 1;
  for (let v = 0; v < words.length; ++v) {
    const value = words[v];
    if (valueBits < 32 && value >>> valueBits !== 0) fail(`vertex ${v}: bits set above tupleBits + weightBits = ${valueBits}`, v);
    const code = (value & codeMask) >>> 0, tuple = weightBits >= 32 ? 0 : value >>> weightBits;
    if (tuple >= lutSize) fail(`vertex ${v}: tuple index ${tuple} >= tuple table size ${lutSize}`, v);
    if (!decodeWeightCode(codec, code, weights, v * 4)) fail(`vertex ${v}: weight code ${code} is not a valid ${codec.method} code`, v);
    writeJoints(k, lut, tuple, joints, weights, v * 4, v);
  }
}

// Two words a vertex: Number arithmetic below 2^53, BigInt above.
function decodeWordsWide(codec, words, lut, lutSize, joints, weights) {
  const k = codec.influences, valueBits = codec.tupleBits + codec.weightBits, wide = !codec.number;
  const vertexCount = words.length / codec.wordsPerVertex;
  const limit = wide ? 1n << BigInt(valueBits) : 2 ** valueBits;
  const codeRange = wide ? 1n << BigInt(codec.weightBits) : 2 ** codec.weightBits;
  for (let v = 0; v < vertexCount; ++v) {
    const value = splitValue(codec, words, v);
    if (value >= limit) fail(`vertex ${v}: bits set above tupleBits + weightBits = ${valueBits}`, v);
    const code = value % codeRange;
    const tuple = wide ? Number(value / codeRange) : Math.floor(value / codeRange);
    if (tuple >= lutSize) fail(`vertex ${v}: tuple index ${tuple} >= tuple table size ${lutSize}`, v);
    if (!decodeWeightCode(codec, code, weights, v * 4)) fail(`vertex ${v}: weight code ${code} is not a valid ${codec.method} code`, v);
    writeJoints(k, lut, tuple, joints, weights, v * 4, v);
  }
}

/**
 * Checks the tuple table (lutSize entries of K joints): tupleBits, every entry below jointCount.
 * @param {object} codec  from codecFromExtension
 * @param {Uint8Array|Uint16Array} lut
 */
export function checkTupleTable(codec, lut) {
  const k = codec.influences;
  if (lut.length === 0 || lut.length % k !== 0) fail(`tuple table has ${lut.length} joints, not a multiple of ${k}`);
  const lutSize = lut.length / k;
  const expected = indexBits(lutSize);
  if (codec.tupleBits !== expected)
    fail(`"tupleBits" = ${codec.tupleBits} but the tuple table has ${lutSize} entries (${expected} bits)`);
  for (let i = 0; i < lut.length; ++i)
    if (lut[i] >= codec.jointCount)
      fail(`tuple table entry ${Math.floor(i / k)} has joint ${lut[i]} >= "jointCount" ${codec.jointCount}`, Math.floor(i / k));
  return lutSize;
}

/**
 * Decodes a primitive's packed words into 4 joints and 4 weights a vertex, exactly as
 * `skinpack decompress` writes JOINTS_0/WEIGHTS_0 (zero-weight slots get joint 0; slots K+1..4
 * are joint 0, weight 0).
 * @param {object} codec  from codecFromExtension
 * @param {Uint32Array} words  wordsPerVertex × vertexCount
 * @param {Uint8Array|Uint16Array} lut  the tuple table, K joints an entry
 * @returns {{joints: Uint16Array, weights: Float32Array, vertexCount: number}}
 */
export function decodeSkin(codec, words, lut) {
  const k = codec.influences, per = codec.wordsPerVertex;
  if (words.length % per !== 0) fail(`"vertices" has ${words.length} words, not ${per} a vertex`);
  const vertexCount = words.length / per;
  const lutSize = checkTupleTable(codec, lut);
  const joints = new Uint16Array(vertexCount * 4);
  const weights = new Float32Array(vertexCount * 4);
  if (per === 1 && codec.number) decodeWords32(codec, words, lut, lutSize, joints, weights);
  else decodeWordsWide(codec, words, lut, lutSize, joints, weights);
  return { joints, weights, vertexCount };
}

/** Bits a vertex of the packed skin, the table included (as `skinpack info` reports). */
export function packedBitsPerVertex(codec, vertexCount, lutLength, lutBytesPerJoint) {
  return codec.tupleBits + codec.weightBits + (lutLength * lutBytesPerJoint * 8) / vertexCount;
}
