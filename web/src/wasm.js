// wasm.js - libskinpack's decode side as WebAssembly: the one implementation of the format's
// rules (sp_validate_packed, sp_codec_from_params, sp_format_validation) and its decoders, built
// from native/ into ../wasm/skinpack.wasm (by the repository's build, or `npm run build:wasm`).
//
// The module is loaded and instantiated once, when this file is first imported (a top-level
// await: node reads the file, a browser fetches it next to this module), so every function here
// is synchronous. Each call copies its arrays into the module's memory (which grows as needed),
// runs the library and frees what it allocated, so memory is reused from call to call.

const WASM_URL = new URL('../wasm/skinpack.wasm', import.meta.url);
const MISSING = 'build it with `npm run build:wasm` in web/ or the repository\'s ./build.sh';

export class SkinpackDecodeError extends Error {
  /**
   * @param {string} message  the library's message (field, value, where)
   * @param {number} [vertex]  vertex (or tuple table entry) the error is at
   * @param {string} [field]  the extension property or array ("vertices", "weightBits", …)
   */
  constructor(message, vertex, field) {
    super(message);
    this.name = 'SkinpackDecodeError';
    this.vertex = vertex;
    this.field = field;
  }
}

async function wasmBytes() {
  if (WASM_URL.protocol === 'file:') {
    const { readFile } = await import('node:fs/promises');
    try {
      return await readFile(WASM_URL);
    } catch (error) {
      throw new Error(`skinpack-web: cannot read ${WASM_URL.pathname} (${error.code}); ${MISSING}`);
    }
  }
  const response = await fetch(WASM_URL);
  if (!response.ok) throw new Error(`skinpack-web: ${WASM_URL} answered ${response.status}; ${MISSING}`);
  return response.arrayBuffer();
}

// The WASI functions the C library links (stdio behind snprintf) are never called by the decode
// side; each import is a stub that throws, so reaching one fails loudly instead of doing nothing.
function unreachableImports(module) {
  const imports = {};
  for (const { module: name, name: field, kind } of WebAssembly.Module.imports(module)) {
    if (kind !== 'function') throw new Error(`skinpack-web: skinpack.wasm imports ${kind} ${name}.${field}`);
    (imports[name] ??= {})[field] = () => { throw new Error(`skinpack-web: skinpack.wasm called ${name}.${field}`); };
  }
  return imports;
}

const module = await WebAssembly.compile(await wasmBytes());
const lib = (await WebAssembly.instantiate(module, unreachableImports(module))).exports;

// Views of the module's memory are made after the last allocation (growth detaches old ones).
function heap(Type, pointer, length) {
  return new Type(lib.memory.buffer, pointer, length);
}

function cString(pointer) {
  const bytes = heap(Uint8Array, pointer);
  return new TextDecoder().decode(bytes.subarray(0, bytes.indexOf(0)));
}

// Allocations of one call, freed together (the library allocates nothing itself).
class Arena {
  constructor() { this.pointers = []; }
  alloc(bytes) {
    const pointer = lib.malloc(Math.max(bytes, 1));
    if (!pointer) throw new RangeError(`skinpack-web: WebAssembly memory exhausted (${bytes} bytes)`);
    this.pointers.push(pointer);
    return pointer;
  }
  copy(array) { // a typed array into the module's memory
    const pointer = this.alloc(array.byteLength);
    heap(Uint8Array, pointer, array.byteLength).set(new Uint8Array(array.buffer, array.byteOffset, array.byteLength));
    return pointer;
  }
  string(text) {
    const bytes = new TextEncoder().encode(text);
    const pointer = this.alloc(bytes.length + 1);
    heap(Uint8Array, pointer, bytes.length + 1).set(bytes);
    heap(Uint8Array, pointer + bytes.length, 1)[0] = 0;
    return pointer;
  }
  free() { for (const pointer of this.pointers) lib.free(pointer); this.pointers.length = 0; }
}

function withArena(run) {
  const arena = new Arena();
  try {
    return run(arena);
  } finally {
    arena.free();
  }
}

// ---- library facts -----------------------------------------------------------------------------

/** The method names in sp_method order (sp_method_name). */
export const METHODS = [];
for (let id = 0, name; (name = lib.sp_method_name(id)); ++id) METHODS.push(cString(name));

/** SP_VERSION of the module (100 for format 1.0). */
export const LIBRARY_VERSION = lib.sp_version();

/** sp_method_from_name: the method id of a name, METHODS.length if unknown. */
export function methodId(name) {
  return withArena((arena) => lib.sp_method_from_name(arena.string(String(name))));
}

/** sp_parse_decimal: a large integer written as a decimal string (spec 1.0, "Large integers"),
 *  as a BigInt, or null when the string breaks the rule (sign, leading zero, <= 2^53, > 2^64 - 1). */
export function parseDecimal(text) {
  return withArena((arena) => {
    const bytes = new TextEncoder().encode(text);
    const out = arena.alloc(8);
    const ok = lib.sp_parse_decimal(arena.string(text), bytes.length, out) === 0;
    return ok ? heap(BigUint64Array, out, 1)[0] : null;
  });
}

/** sp_joint_bytes: bytes of a tupleTable component (and of JOINTS_0): 1, 2, or 0 for no valid count. */
export function jointBytes(jointCount) {
  return Number.isInteger(jointCount) && jointCount >= 0 && jointCount < 2 ** 32 ? lib.sp_joint_bytes(jointCount) : 0;
}

/** sp_words_per_vertex: 32-bit words a vertex for these widths; 0 if they do not fit 64 bits. */
export function wordsPerVertex(tupleBits, weightBits) {
  return lib.sp_words_per_vertex(tupleBits >>> 0, weightBits >>> 0);
}

// ---- one primitive through the library -----------------------------------------------------------

const FIELD_VERTICES = 9, FIELD_TUPLE_TABLE = 10; // sp_field: the report's index is a vertex / table entry
const CODEC_VALUES = 14; // spw_codec_values

/**
 * The declared parameters of one primitive, as read from the extension's JSON (decode.js
 * extensionParams): method (id), influences, jointCount, weightBits, tupleBits (integers), n
 * (BigInt), axisSamples (BigInt[]), maxError (number or undefined).
 * @typedef {{method: number, influences: number, jointCount: number, weightBits: number,
 *   tupleBits: number, n: bigint, axisSamples: bigint[], maxError?: number}} PackedParams
 */

function setParams(call, p) {
  const axes = p.axisSamples || [];
  const u64 = (x) => BigInt.asUintN(64, BigInt(x));
  lib.spw_set_params(call, p.method >>> 0, u64(p.influences), u64(p.jointCount), u64(p.weightBits), u64(p.tupleBits),
                     u64(p.n), axes.length, u64(axes[0] ?? 0n), u64(axes[1] ?? 0n), u64(axes[2] ?? 0n),
                     p.maxError === undefined ? 0 : 1, p.maxError ?? 0);
}

// The codec the library reported, in the shape the GPU path's uniforms and the viewer read.
function reportedCodec(call, arena, params) {
  const out = arena.alloc(8 * CODEC_VALUES);
  lib.spw_codec_values(call, out);
  const v = heap(BigUint64Array, out, CODEC_VALUES);
  if (Number(v[13]) !== CODEC_VALUES) throw new Error('skinpack-web: skinpack.wasm has another codec layout');
  const methodIndex = Number(v[0]), influences = Number(v[1]);
  const axisSamples = Array.from(v.subarray(8, 11)).filter((q) => q > 0n);
  return {
    method: METHODS[methodIndex], methodId: methodIndex, influences, jointCount: Number(params.jointCount),
    weightBits: Number(v[2]), tupleBits: Number(params.tupleBits),
    wordsPerVertex: wordsPerVertex(Number(params.tupleBits), Number(v[2])),
    componentBits: Array.from(v.subarray(3, 7), Number), n: Number(v[7]), nBig: v[7],
    axisSamples, axisNumbers: axisSamples.map(Number), scale: v[11], maxCode: v[12], maxCodeNumber: Number(v[12]),
    maxError: lib.spw_codec_max_error(call), params,
  };
}

function refusal(call) {
  const field = lib.spw_report_field(call);
  const index = lib.spw_report_index(call);
  const at = field === FIELD_VERTICES || field === FIELD_TUPLE_TABLE ? index : undefined;
  throw new SkinpackDecodeError(cString(lib.spw_message(call)), at, cString(lib.sp_field_name(field)));
}

function withCall(run) {
  return withArena((arena) => {
    const call = lib.spw_call_create();
    if (!call) throw new RangeError('skinpack-web: WebAssembly memory exhausted');
    try {
      return run(call, arena);
    } finally {
      lib.spw_call_destroy(call);
    }
  });
}

/**
 * The codec of the declared parameters alone, checked as far as they go without the arrays
 * (every parameter's range, the method's rules for n and axisSamples, weightBits against the
 * codec); validate()/decode() check the rest. Throws SkinpackDecodeError with the library's message.
 * @param {PackedParams} params
 */
export function codecFromParams(params) {
  return withCall((call, arena) => {
    setParams(call, params);
    if (lib.spw_check_params(call) !== 0) refusal(call);
    return reportedCodec(call, arena, params);
  });
}

/**
 * sp_packed_params_equal: whether two primitives' declared parameters are the same (those
 * sharing a "vertices" accessor must declare the same, meshlets aside).
 * @param {PackedParams} a  @param {PackedParams} b
 */
export function paramsEqual(a, b) {
  return withCall((first) => withCall((second) => {
    setParams(first, a);
    setParams(second, b);
    return lib.spw_params_equal(first, second) === 1;
  }));
}

/**
 * One stored primitive: the parameters and the two accessors' arrays.
 * @typedef {{params: PackedParams, words: Uint32Array, wordsPerVertex: number,
 *   primitiveVertexCount?: number, lut: Uint8Array|Uint16Array, lutComponents: number,
 *   skinJointCount?: number}} PackedPrimitive
 * words: the "vertices" accessor (wordsPerVertex = its component count); lut: the
 * "tupleTable" accessor (lutComponents = its component count; its array type gives the
 * component size); primitiveVertexCount: the primitive's POSITION count (default: the packed
 * count); skinJointCount: joints of the smallest skin of the nodes using the mesh (0: none).
 */

function setArrays(call, arena, primitive) {
  const { words, lut } = primitive;
  const perVertex = primitive.wordsPerVertex, components = primitive.lutComponents;
  if (!(words instanceof Uint32Array)) throw new SkinpackDecodeError('vertices: not UNSIGNED_INT words', undefined, 'vertices');
  if (!(lut instanceof Uint8Array || lut instanceof Uint16Array))
    throw new SkinpackDecodeError('tupleTable: not UNSIGNED_BYTE or UNSIGNED_SHORT joints', undefined, 'tupleTable');
  if (!(perVertex >= 1) || words.length % perVertex)
    throw new SkinpackDecodeError(`vertices: ${words.length} words are not ${perVertex} a vertex`, undefined, 'vertices');
  if (!(components >= 1) || lut.length % components)
    throw new SkinpackDecodeError(`tupleTable: ${lut.length} joints are not ${components} an entry`, undefined, 'tupleTable');
  const vertexCount = words.length / perVertex;
  const wordsAt = arena.copy(words);
  const lutAt = arena.alloc(lut.length * 2);
  heap(Uint16Array, lutAt, lut.length).set(lut); // widened to u16, as sp_packed_primitive takes it
  lib.spw_set_words(call, wordsAt, vertexCount, perVertex, primitive.primitiveVertexCount ?? vertexCount);
  lib.spw_set_table(call, lutAt, lut.length / components, components, lut.BYTES_PER_ELEMENT, primitive.skinJointCount ?? 0);
  return vertexCount;
}

/**
 * Validates one primitive completely (sp_validate_packed: parameters, layout, table, every
 * vertex) without keeping the decoded skin. Returns the codec; throws SkinpackDecodeError.
 * @param {PackedPrimitive} primitive
 */
export function validate(primitive) {
  return withCall((call, arena) => {
    setParams(call, primitive.params);
    setArrays(call, arena, primitive);
    if (lib.spw_validate(call, 0, 0) !== 0) refusal(call);
    return reportedCodec(call, arena, primitive.params);
  });
}

/**
 * Validates and decodes one primitive into 4 joints and 4 weights a vertex, laid out as
 * `skinpack decompress` writes JOINTS_0/WEIGHTS_0 (a slot without weight, or past K, has joint
 * 0 and weight 0): new arrays three.js can use as skinIndex/skinWeight.
 * @param {PackedPrimitive} primitive
 * @param {{jointBytes?: number}} [options]  joint array width: 1 (Uint8Array) or 2 (Uint16Array);
 *   default as glTF stores JOINTS_0 for the declared jointCount (sp_joint_bytes)
 * @returns {{codec: object, joints: Uint8Array|Uint16Array, weights: Float32Array, vertexCount: number}}
 */
export function decode(primitive, options = {}) {
  return withCall((call, arena) => {
    setParams(call, primitive.params);
    const vertexCount = setArrays(call, arena, primitive);
    // Room for 4 slots a vertex; the library writes K (K > 4 is refused before anything is written).
    const jointsAt = arena.alloc(vertexCount * 8), weightsAt = arena.alloc(vertexCount * 16);
    if (lib.spw_validate(call, jointsAt, weightsAt) !== 0) refusal(call);
    const codec = reportedCodec(call, arena, primitive.params);
    const width = options.jointBytes ?? jointBytes(codec.jointCount);
    if (width !== 2 && !(width === 1 && jointBytes(codec.jointCount) === 1))
      throw new RangeError(`skinpack-web: jointBytes ${width} cannot hold the joints of jointCount ${codec.jointCount}`);
    lib.spw_expand(jointsAt, weightsAt, vertexCount, codec.influences, width);
    const Joints = width === 1 ? Uint8Array : Uint16Array;
    const joints = heap(Joints, jointsAt, vertexCount * 4).slice(), weights = heap(Float32Array, weightsAt, vertexCount * 4).slice();
    return { codec, joints, weights, vertexCount };
  });
}

/** Bytes the module's memory holds now (it grows as calls need and is reused after them). */
export function wasmMemoryBytes() {
  return lib.memory.buffer.byteLength;
}
