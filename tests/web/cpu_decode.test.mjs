// cpu_decode.test.mjs - web/src/decode.js (the library as WebAssembly behind it) against
// `skinpack decompress`, bit for bit, on every case of cases.mjs; and its refusals of broken
// data with the library's messages. The conformance vectors are wasm.test.mjs's.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readGltf, readAccessor } from './gltf_file.mjs';
import { allCases, ASSETS } from './cases.mjs';
import { codecFromExtension, decodeSkin, SKINPACK_EXTENSION } from '../../web/src/decode.js';
import { CONFORMANCE, float32Hex } from './conformance.mjs';
import { existsSync } from 'node:fs';
import { readdirSync, readFileSync } from 'node:fs';

// A SkinpackDecodeError whose message (the library's, without the class name) matches pattern.
function throwsMessage(run, pattern, label) {
  assert.throws(run, (error) => {
    assert.equal(error.name, 'SkinpackDecodeError', label);
    assert.match(error.message, pattern, label);
    return true;
  }, label);
}

function packedPrimitives(file) {
  const out = [];
  file.json.meshes.forEach((mesh, m) => mesh.primitives.forEach((primitive, p) => {
    const ext = primitive.extensions && primitive.extensions[SKINPACK_EXTENSION];
    if (ext) out.push({ m, p, primitive, ext });
  }));
  return out;
}

function decodePrimitive(file, ext) {
  const codec = codecFromExtension(ext);
  return { codec, ...decodeSkin(codec, readAccessor(file, ext.vertices), readAccessor(file, ext.tupleTable)) };
}

test('assets are given', () => assert.ok(ASSETS.length >= 1, 'SKINPACK_WEB_ASSETS lists no asset'));

const cases = allCases();
const widths = { 1: 0, 2: 0 };
for (const c of cases) {
  test(`CPU decode equals skinpack decompress: ${c.name}`, () => {
    const packed = readGltf(c.packed), decoded = readGltf(c.decoded);
    const primitives = packedPrimitives(packed);
    assert.ok(primitives.length > 0, 'no packed primitive');
    for (const { m, p, ext } of primitives) {
      const result = decodePrimitive(packed, ext);
      widths[result.codec.wordsPerVertex]++;
      const attributes = decoded.json.meshes[m].primitives[p].attributes;
      const joints = readAccessor(decoded, attributes.JOINTS_0), weights = readAccessor(decoded, attributes.WEIGHTS_0);
      assert.equal(result.joints.length, joints.length, `mesh ${m} primitive ${p}: vertex count`);
      const ours = new Uint32Array(result.weights.buffer), theirs = new Uint32Array(weights.buffer);
      for (let i = 0; i < joints.length; ++i) {
        if (result.joints[i] !== joints[i] || ours[i] !== theirs[i])
          assert.fail(`mesh ${m} primitive ${p} vertex ${i >> 2} slot ${i & 3}: JS joint ${result.joints[i]} weight ` +
                      `${result.weights[i]}, skinpack decompress joint ${joints[i]} weight ${weights[i]}`);
      }
    }
  });
}

test('one- and two-word vertices were exercised', () => {
  assert.ok(widths[1] > 0 && widths[2] > 0, JSON.stringify(widths));
});

// ---- refusals ---------------------------------------------------------------------------------

function foxPrimitive() {
  const fox = cases.find((c) => c.name === 'Fox_fallback');
  const file = readGltf(fox.packed);
  const { ext } = packedPrimitives(file)[0];
  return { ext, words: readAccessor(file, ext.vertices), lut: readAccessor(file, ext.tupleTable) };
}

test('bad extension fields are refused, naming the field', () => {
  const { ext } = foxPrimitive();
  const bad = [ // the library's messages, but for what the JSON reader checks (types, presence)
    [{ influences: 5 }, /^influences: 5 above the maximum 4$/], [{ jointCount: 0 }, /^jointCount: 0 below the minimum 1$/],
    [{ method: 'zip' }, /^method: unknown method$/], [{ weightBits: 65 }, /^weightBits: 65 above the maximum 64$/],
    [{ weightBits: ext.weightBits + 1 }, /^weightBits: \d+ contradicts the other parameters or the data \(expected \d+\)$/],
    [{ tupleBits: 33 }, /^tupleBits: 33 above the maximum 32$/], [{ n: 1 }, /^n: 1 below the minimum 2$/],
    [{ n: 1.5 }, /^"n" = 1.5 must be an integer/], [{ method: 'any', n: 0 }, /^axisSamples: 0 contradicts .*\(expected 3\) at axis 0$/],
    [{ vertices: undefined }, /"vertices" missing/], [{ influences: -1 }, /"influences" = -1 must be a non-negative integer/],
    [{ method: 4 }, /"method" = 4 must be a string/],
  ];
  for (const [change, pattern] of bad) throwsMessage(() => codecFromExtension({ ...ext, ...change }), pattern, JSON.stringify(change));
});

test('bad words and tables are refused, naming the vertex', () => {
  const { ext, words, lut } = foxPrimitive();
  const codec = codecFromExtension(ext);
  const valueBits = ext.tupleBits + ext.weightBits;
  const refused = (w, l, pattern, vertex) => assert.throws(() => decodeSkin(codec, w, l), (error) => {
    assert.equal(error.name, 'SkinpackDecodeError');
    assert.match(error.message, pattern);
    assert.equal(error.vertex, vertex, error.message);
    return true;
  });
  if (valueBits < 32) {
    const padded = words.slice(); padded[7] |= 1 << 31;
    refused(padded, lut, new RegExp(`^vertices: bits set above the ${valueBits} used bits at vertex 7$`), 7);
  }
  const tupleOut = words.slice(); tupleOut[3] = ((lut.length / ext.influences) * 2 ** ext.weightBits) >>> 0;
  refused(tupleOut, lut, /^vertices: tuple index \d+ not below the table's \d+ tuples at vertex 3$/, 3);
  const codeOut = words.slice(); codeOut[5] = (codeOut[5] - (codeOut[5] % 2 ** ext.weightBits) + 2 ** ext.weightBits - 1) >>> 0;
  refused(codeOut, lut, /^vertices: weight code \d+ above the largest code \d+ at vertex 5$/, 5);
  const badLut = lut.slice(); badLut[2] = ext.jointCount;
  refused(words, badLut, new RegExp(`^tupleTable: joint ${ext.jointCount} not below jointCount ${ext.jointCount} at tuple 0$`), 0);
  refused(words, lut.subarray(0, ext.influences), /^tupleBits: \d+ contradicts the other parameters or the data \(expected 0\)$/, undefined);
});

// ---- spec 1.0 conformance ---------------------------------------------------------------------

const examples = existsSync(`${CONFORMANCE}examples/`);
test('the conformance example files decode to their expected joints and weights', { skip: !examples && 'no examples' }, () => {
  const folder = `${CONFORMANCE}examples/`;
  const examples = readdirSync(folder).filter((f) => f.endsWith('.json'));
  assert.ok(examples.length >= 3);
  for (const name of examples) {
    const expected = JSON.parse(readFileSync(folder + name, 'utf8'));
    const file = readGltf(folder + name.replace(/\.json$/, '.glb'));
    for (const primitive of expected.primitives) {
      const ext = file.json.meshes[primitive.mesh].primitives[primitive.primitive].extensions[SKINPACK_EXTENSION];
      const { joints, weights } = decodePrimitive(file, ext);
      const k = ext.influences;
      primitive.joints.forEach((slots, v) => {
        assert.deepEqual(Array.from(joints.subarray(4 * v, 4 * v + k)), slots, `${name} vertex ${v}: joints`);
        assert.deepEqual(Array.from(weights.subarray(4 * v, 4 * v + k), float32Hex), primitive.weights[v], `${name} vertex ${v}: weights`);
      });
    }
  }
});

test('large integers: strings above 2^53 only', () => {
  const base = { vertices: 0, tupleTable: 0, influences: 2, jointCount: 1, method: 'oss', tupleBits: 0 };
  assert.equal(codecFromExtension({ ...base, n: '9223372036854775808', weightBits: 63 }).nBig, 2n ** 63n);
  assert.throws(() => codecFromExtension({ ...base, n: '1063', weightBits: 11 }), /"n" = "1063"/);
  assert.throws(() => codecFromExtension({ ...base, n: 2 ** 60, weightBits: 60 }), /"n" = \d+ must be an integer \(a JSON number up to 2\^53/);
  assert.throws(() => codecFromExtension({ ...base, n: '18446744073709551616', weightBits: 64 }), /"n"/);
  throwsMessage(() => codecFromExtension({ ...base, n: 1063, weightBits: 11, axisSamples: [2] }), /^axisSamples: 1 contradicts the other parameters or the data \(expected 0\) at axis 0$/);
});
