// wasm.test.mjs - libskinpack's decode side as WebAssembly (web/src/wasm.js):
//  * every conformance vector (docs/extension/conformance/weights.jsonl) decodes to exactly the
//    C values (float32 bits), with the codec the spec lists, and every invalid one is refused
//    with the library's message;
//  * truncated, mistyped and garbage inputs are refused with a SkinpackDecodeError (never a
//    WebAssembly trap, never a silently decoded skin that breaks the format's invariants);
//  * the module's memory is reused from call to call.
import { test } from 'node:test';
import { readFileSync } from 'node:fs';
import assert from 'node:assert/strict';
import { allCases } from './cases.mjs';
import { readAccessor, readGltf } from './gltf_file.mjs';
import { float32Hex, readVectors } from './conformance.mjs';
import { extensionParams, SKINPACK_EXTENSION } from '../../web/src/decode.js';
import { codecFromParams, decode, SkinpackDecodeError, validate, wasmMemoryBytes } from '../../web/src/wasm.js';

// One vertex holding one code: tuple index 0 of a table whose entry lists joints 0..K-1.
function oneVertex(ext, code) {
  const params = extensionParams(ext);
  const k = ext.influences, perVertex = ext.weightBits > 32 ? 2 : 1;
  const words = perVertex === 1 ? new Uint32Array([Number(code)]) : new Uint32Array([Number(code & 0xffffffffn), Number(code >> 32n)]);
  return { params: { ...params, jointCount: 4 }, words, wordsPerVertex: perVertex, lut: Uint8Array.from({ length: k }, (_, s) => s), lutComponents: k };
}

function refusedWith(run, message, label) {
  assert.throws(run, (error) => {
    assert.ok(error instanceof SkinpackDecodeError, `${label}: ${error}`);
    assert.equal(error.message, message, label);
    assert.equal(error.field, message.split(':')[0], `${label}: field`); // the library's sp_field_name
    return true;
  }, label);
}

test('the module imports only WASI functions (stubs that throw), and exports its memory', () => {
  const module = new WebAssembly.Module(readFileSync(new URL('../../web/wasm/skinpack.wasm', import.meta.url)));
  const imports = WebAssembly.Module.imports(module);
  assert.ok(imports.every((i) => i.module === 'wasi_snapshot_preview1' && i.kind === 'function'), JSON.stringify(imports));
  assert.ok(WebAssembly.Module.exports(module).some((e) => e.name === 'memory' && e.kind === 'memory'));
});

const vectors = readVectors();
const CONFORMANCE_TEST = 'every conformance vector decodes to the C values through WebAssembly, or is refused with the library\'s message';
test(CONFORMANCE_TEST, { skip: !vectors && 'no docs/extension/conformance' }, () => {
  let valid = 0, invalid = 0;
  for (const { vector, ext, code } of vectors) {
    const label = `${vector.method} K=${vector.influences} n=${vector.n} code ${vector.code}`;
    const k = vector.influences;
    const codec = codecFromParams(extensionParams(ext));
    assert.equal(codec.maxCode, BigInt(vector.maxCode), `${label}: largest code`);
    assert.equal(codec.weightBits, vector.weightBits, `${label}: weight bits`);
    if (vector.method !== 'any') assert.equal(codec.scale, BigInt(vector.scale), `${label}: grid denominator`);
    const primitive = oneVertex(ext, code);
    if (!vector.valid) {
      const why = vector.reason === 'above maxCode' ? `above the largest code ${vector.maxCode}` : 'outside the simplex';
      assert.ok(vector.reason === 'above maxCode' || vector.reason === 'outside the simplex', vector.reason);
      refusedWith(() => decode(primitive), `vertices: weight code ${vector.code} ${why} at vertex 0`, label);
      refusedWith(() => validate(primitive), `vertices: weight code ${vector.code} ${why} at vertex 0`, label);
      invalid++;
      continue;
    }
    const { joints, weights } = decode(primitive);
    assert.deepEqual(Array.from(weights.subarray(0, k), float32Hex), vector.weights, `${label}: weights`);
    assert.deepEqual(Array.from(weights.subarray(k)), new Array(4 - k).fill(0), `${label}: slots past K`);
    assert.deepEqual(Array.from(joints), [0, 1, 2, 3].map((j) => (j < k && weights[j] > 0 ? j : 0)), `${label}: joints`);
    assert.equal(validate(primitive).maxCode, codec.maxCode);
    valid++;
  }
  assert.ok(valid > 1000 && invalid > 300, `${valid} valid, ${invalid} invalid vectors`);
});

// ---- broken inputs -----------------------------------------------------------------------------

const cases = allCases();
function packedOf(name) {
  const file = readGltf(cases.find((c) => c.name === name).packed);
  const primitive = file.json.meshes[0].primitives[0];
  const ext = primitive.extensions[SKINPACK_EXTENSION];
  const words = readAccessor(file, ext.vertices), lut = readAccessor(file, ext.tupleTable);
  const wordsPerVertex = ext.tupleBits + ext.weightBits > 32 ? 2 : 1;
  return { ext, primitive: { params: extensionParams(ext), words, wordsPerVertex, lut, lutComponents: ext.influences,
    primitiveVertexCount: words.length / wordsPerVertex, skinJointCount: file.json.skins[0].joints.length } };
}

test('truncated and mistyped arrays are refused, naming the array', () => {
  const { ext, primitive } = packedOf('Fox_fallback');
  const count = primitive.primitiveVertexCount, k = ext.influences;
  refusedWith(() => decode({ ...primitive, words: primitive.words.subarray(0, count - 1) }),
              `vertices: ${count - 1} packed vertices, the primitive has ${count}`, 'one word short');
  refusedWith(() => decode({ ...primitive, words: new Uint32Array(0), primitiveVertexCount: 0 }),
              'vertices: 0 packed vertices, the primitive has 0', 'no words');
  refusedWith(() => decode({ ...primitive, lut: primitive.lut.subarray(0, 0) }), 'tupleTable: index 0 not below 1 at tuple 0', 'no table');
  refusedWith(() => decode({ ...primitive, lut: primitive.lut.subarray(0, k * 3) }),
              `tupleBits: ${ext.tupleBits} contradicts the other parameters or the data (expected 2)`, 'table cut to 3 entries');
  refusedWith(() => decode({ ...primitive, lut: primitive.lut.subarray(0, k * 3 + 1) }),
              `tupleTable: ${k * 3 + 1} joints are not ${k} an entry`, 'table cut inside an entry');
  refusedWith(() => decode({ ...primitive, wordsPerVertex: 2, words: primitive.words.subarray(0, count - 1) }),
              `vertices: ${count - 1} words are not 2 a vertex`, 'odd word count for two words a vertex');
  refusedWith(() => decode({ ...primitive, wordsPerVertex: 2, primitiveVertexCount: count / 2 }),
              'vertices: 2 contradicts the other parameters or the data (expected 1) at vertex 0', 'VEC2 words for a 32-bit codec');
  refusedWith(() => decode({ ...primitive, lutComponents: k - 1, lut: primitive.lut.subarray(0, (k - 1) * 24) }),
              `tupleBits: ${ext.tupleBits} contradicts the other parameters or the data (expected 5)`, 'VEC3 table');
  refusedWith(() => decode({ ...primitive, lut: Uint16Array.from(primitive.lut) }),
              'tupleTable: 2 contradicts the other parameters or the data (expected 1) at tuple 0', 'UNSIGNED_SHORT table for 24 joints');
  refusedWith(() => decode({ ...primitive, skinJointCount: ext.jointCount - 1 }),
              `jointCount: ${ext.jointCount} contradicts the other parameters or the data (expected ${ext.jointCount - 1})`, 'smaller skin');
  refusedWith(() => decode({ ...primitive, words: new Float32Array(primitive.words.length) }), 'vertices: not UNSIGNED_INT words', 'float words');
  refusedWith(() => decode({ ...primitive, lut: new Int16Array(primitive.lut.length) }),
              'tupleTable: not UNSIGNED_BYTE or UNSIGNED_SHORT joints', 'signed table');
});

// A small deterministic generator (xorshift32), so a failure reproduces.
function generator(seed) {
  let x = seed >>> 0 || 1;
  return () => { x ^= x << 13; x >>>= 0; x ^= x >>> 17; x ^= x << 5; x >>>= 0; return x; };
}

// A decoded skin that passed validation must satisfy the format: weights non-negative, summing
// to 1 (float rounding), sorted but for Any (whose axes are sampled independently), every joint
// with weight below jointCount and used once.
function assertValidSkin(result, jointCount, label) {
  const { codec, joints, weights, vertexCount } = result;
  const sorted = codec.method !== 'any';
  for (let v = 0; v < vertexCount; ++v) {
    let sum = 0;
    for (let s = 0; s < 4; ++s) {
      const w = weights[4 * v + s];
      assert.ok(w >= 0 && (!sorted || s === 0 || w <= weights[4 * v + s - 1]), `${label} vertex ${v}: weights ${weights.subarray(4 * v, 4 * v + 4)}`);
      sum += w;
      if (w > 0) {
        assert.ok(joints[4 * v + s] < jointCount, `${label} vertex ${v}: joint ${joints[4 * v + s]}`);
        for (let t = 0; t < s; ++t) assert.ok(!(weights[4 * v + t] > 0 && joints[4 * v + t] === joints[4 * v + s]), `${label} vertex ${v}: joint twice`);
      }
    }
    assert.ok(Math.abs(sum - 1) < 1e-5, `${label} vertex ${v}: weights sum to ${sum}`);
  }
}

test('garbage words, tables and parameters: refused or decoded to a valid skin, never a trap', () => {
  const next = generator(12);
  const seen = { refused: 0, decoded: 0 };
  for (const name of ['Fox_fallback', 'Fox_oss64', 'Fox_any22', 'Fox_pot40', 'Fox_k2']) {
    const { ext, primitive } = packedOf(name);
    for (let round = 0; round < 120; ++round) {
      const words = primitive.words.slice(), lut = primitive.lut.slice(), params = { ...primitive.params };
      const kind = round % 4;
      if (kind === 0) for (let i = 0; i < 1 + (next() % 4); ++i) words[next() % words.length] = next(); // a few words
      if (kind === 1) for (let i = 0; i < words.length; ++i) words[i] = next(); // every word
      if (kind === 2) lut[next() % lut.length] = next() % (ext.jointCount + 2);
      if (kind === 3) { // one declared parameter
        const field = ['influences', 'jointCount', 'weightBits', 'tupleBits', 'method'][next() % 5];
        params[field] = field === 'method' ? next() % 7 : next() % 70;
        if (next() % 2) params.n = BigInt(next()) * BigInt(next());
      }
      const label = `${name} round ${round}`;
      try {
        assertValidSkin(decode({ ...primitive, words, lut, params }), Number(params.jointCount), label);
        seen.decoded++;
      } catch (error) {
        if (!(error instanceof SkinpackDecodeError)) throw error; // a trap (RuntimeError) or a failed invariant
        assert.match(error.message, /^[a-zA-Z]+: /, label);
        seen.refused++;
      }
    }
  }
  assert.ok(seen.refused > 300 && seen.decoded > 20, JSON.stringify(seen));
});

test('the module\'s memory is reused: repeated decodes do not grow it', () => {
  const { primitive } = packedOf('Fox_oss64');
  decode(primitive);
  const before = wasmMemoryBytes();
  for (let i = 0; i < 50; ++i) {
    decode(primitive);
    try { decode({ ...primitive, words: primitive.words.subarray(2) }); } catch { /* refused, freed too */ }
  }
  assert.equal(wasmMemoryBytes(), before);
});
