// decode.js - the container side of SKINPACK_packed_skin (docs/extension/README.md) in JS: reading
// the extension's JSON fields into the library's parameters, the compact-mode layout and the
// fallback buffer, and the codec the GPU path sets its uniforms from.
//
// Every format rule (ranges, the methods' parameters, the table, every vertex) and the decoders
// are libskinpack's, run as WebAssembly (wasm.js): this file only turns JSON values into the
// integers the library takes (types a JSON reader must check: integers, large-integer strings
// through the library's sp_parse_decimal, the method name through sp_method_from_name) and keeps
// the names the plugin, the glTF-Transform extension and the viewer import.

import { codecFromParams, decode, jointBytes, methodId, METHODS, parseDecimal, SkinpackDecodeError } from './wasm.js';

export { jointBytes, METHODS, SkinpackDecodeError };
export const SKINPACK_EXTENSION = 'SKINPACK_packed_skin';

function fail(message, field) {
  throw new SkinpackDecodeError(message, undefined, field);
}

const MAX_SAFE = 2 ** 53; // SP_JSON_MAX_SAFE_INTEGER: larger values are decimal strings

/**
 * A non-negative integer property that may exceed 2^53 (spec 1.0, "Large integers"): a JSON
 * number up to 2^53, or a string of decimal digits that the library's sp_parse_decimal accepts
 * (above 2^53, at most 2^64 - 1). Returns a BigInt.
 */
export function parseLargeInteger(value, field) {
  if (typeof value === 'number' && Number.isInteger(value) && value >= 0 && value <= MAX_SAFE) return BigInt(value);
  const parsed = typeof value === 'string' ? parseDecimal(value) : null;
  if (parsed === null)
    fail(`${field} = ${JSON.stringify(value)} must be an integer (a JSON number up to 2^53, a decimal string above)`, field);
  return parsed;
}

function jsonInteger(ext, field) {
  const value = ext[field];
  if (!Number.isInteger(value) || value < 0 || value > MAX_SAFE) fail(`"${field}" = ${JSON.stringify(value)} must be a non-negative integer`, field);
  return value;
}

/**
 * The declared parameters of one primitive's extension object, as the library takes them
 * (wasm.js PackedParams). Throws SkinpackDecodeError for a missing field or a JSON value of
 * the wrong type; the values themselves are the library's to check.
 * @param {object} ext  the primitive's extensions.SKINPACK_packed_skin
 */
export function extensionParams(ext) {
  if (!ext || typeof ext !== 'object') fail('extension object missing');
  for (const field of ['vertices', 'tupleTable', 'influences', 'jointCount', 'method', 'n', 'weightBits', 'tupleBits'])
    if (ext[field] === undefined) fail(`"${field}" missing`, field);
  if (typeof ext.method !== 'string') fail(`"method" = ${JSON.stringify(ext.method)} must be a string`, 'method');
  const axes = ext.axisSamples ?? [];
  if (!Array.isArray(axes) || axes.length > 3) fail('"axisSamples" must be an array of at most 3 integers', 'axisSamples');
  if (ext.maxError !== undefined && typeof ext.maxError !== 'number') fail('"maxError" must be a number', 'maxError');
  const params = {
    method: methodId(ext.method), influences: jsonInteger(ext, 'influences'), jointCount: jsonInteger(ext, 'jointCount'),
    weightBits: jsonInteger(ext, 'weightBits'), tupleBits: jsonInteger(ext, 'tupleBits'), n: parseLargeInteger(ext.n, '"n"'),
    axisSamples: axes.map((q, a) => parseLargeInteger(q, `"axisSamples"[${a}]`)),
  };
  if (ext.maxError !== undefined) params.maxError = ext.maxError;
  return params;
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

/** A buffer without data that only compact primitives' JOINTS_0/WEIGHTS_0 point into. */
export function isFallbackBuffer(buffer) {
  const mark = buffer && buffer.extensions && buffer.extensions[SKINPACK_EXTENSION];
  return !!(mark && mark.fallback === true);
}

/**
 * The codec an extension object declares, from the library (its parameter checks, then
 * sp_codec_from_params): the fields the GPU path's uniforms and the viewer read (method,
 * methodId, influences, weightBits, tupleBits, wordsPerVertex, componentBits, n, scale,
 * maxCode, axisSamples, maxError) and the parsed params. The arrays are checked by decodeSkin
 * (or wasm.js validate/decode). Throws SkinpackDecodeError naming the field.
 * @param {object} ext  the primitive's extensions.SKINPACK_packed_skin
 */
export function codecFromExtension(ext) {
  return codecFromParams(extensionParams(ext));
}

/**
 * Validates and decodes a primitive's packed words into 4 joints (u16) and 4 weights a vertex,
 * exactly as `skinpack decompress` writes JOINTS_0/WEIGHTS_0 (zero-weight slots get joint 0;
 * slots K+1..4 are joint 0, weight 0), through the library.
 * @param {object} codec  from codecFromExtension
 * @param {Uint32Array} words  wordsPerVertex × vertexCount
 * @param {Uint8Array|Uint16Array} lut  the tuple table, K joints an entry
 * @returns {{joints: Uint16Array, weights: Float32Array, vertexCount: number}}
 */
export function decodeSkin(codec, words, lut) {
  // Widths over 64 bits have no word count: one a vertex, and the library refuses the widths.
  const primitive = { params: codec.params, words, wordsPerVertex: codec.wordsPerVertex || 1, lut, lutComponents: codec.influences };
  const { joints, weights, vertexCount } = decode(primitive, { jointBytes: 2 });
  return { joints, weights, vertexCount };
}
