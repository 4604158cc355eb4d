// cpu_decode.test.mjs - web/src/decode.js against `skinpack decompress`, bit for bit, on every
// case of cases.mjs; and its refusals of broken data.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readGltf, readAccessor } from './gltf_file.mjs';
import { allCases, ASSETS } from './cases.mjs';
import { codecFromExtension, decodeSkin, decodeWeightCode, SKINPACK_EXTENSION } from '../../web/src/decode.js';
import { CONFORMANCE, float32Hex, readVectors } from './conformance.mjs';
import { readdirSync, readFileSync } from 'node:fs';

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
const paths = { number: 0, bigint: 0 };
for (const c of cases) {
  test(`CPU decode equals skinpack decompress: ${c.name}`, () => {
    const packed = readGltf(c.packed), decoded = readGltf(c.decoded);
    const primitives = packedPrimitives(packed);
    assert.ok(primitives.length > 0, 'no packed primitive');
    for (const { m, p, ext } of primitives) {
      const result = decodePrimitive(packed, ext);
      paths[result.codec.number ? 'number' : 'bigint']++;
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

test('both arithmetic paths were exercised', () => {
  assert.ok(paths.number > 0 && paths.bigint > 0, JSON.stringify(paths));
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
  const bad = [
    [{ influences: 5 }, /"influences"/], [{ jointCount: 0 }, /"jointCount"/], [{ method: 'zip' }, /"method"/],
    [{ weightBits: 65 }, /"weightBits"/], [{ weightBits: ext.weightBits + 1 }, /"weightBits"/],
    [{ tupleBits: 33 }, /"tupleBits"/], [{ n: 1 }, /"n"/], [{ n: 1.5 }, /"n"/],
    [{ method: 'any', n: 0 }, /"axisSamples"/], [{ vertices: undefined }, /"vertices" missing/],
  ];
  for (const [change, pattern] of bad) assert.throws(() => codecFromExtension({ ...ext, ...change }), pattern, JSON.stringify(change));
});

test('bad words and tables are refused, naming the vertex', () => {
  const { ext, words, lut } = foxPrimitive();
  const codec = codecFromExtension(ext);
  const valueBits = ext.tupleBits + ext.weightBits;
  if (valueBits < 32) {
    const padded = words.slice(); padded[7] |= 1 << 31;
    assert.throws(() => decodeSkin(codec, padded, lut), /vertex 7: bits set above/);
  }
  const tupleOut = words.slice(); tupleOut[3] = ((lut.length / ext.influences) * 2 ** ext.weightBits) >>> 0;
  assert.throws(() => decodeSkin(codec, tupleOut, lut), /vertex 3: (tuple index|bits set)/);
  const codeOut = words.slice(); codeOut[5] = (codeOut[5] - (codeOut[5] % 2 ** ext.weightBits) + 2 ** ext.weightBits - 1) >>> 0;
  assert.throws(() => decodeSkin(codec, codeOut, lut), /vertex 5: weight code \d+ is not a valid oss code/);
  const badLut = lut.slice(); badLut[2] = ext.jointCount;
  assert.throws(() => decodeSkin(codec, words, badLut), /tuple table entry 0 has joint/);
  assert.throws(() => decodeSkin(codec, words, lut.subarray(0, ext.influences)), /"tupleBits"/);
});

// ---- spec 1.0 conformance ---------------------------------------------------------------------

const vectors = readVectors();
test('every conformance vector decodes exactly (integers and float32 bits) or is rejected', { skip: !vectors && 'no docs/extension/conformance' }, () => {
  let valid = 0, invalid = 0;
  for (const { vector, codec, code } of vectors) {
    const weights = new Float32Array(4), grid = [];
    const ok = decodeWeightCode(codec, code, weights, 0, grid);
    const label = `${vector.method} K=${vector.influences} n=${vector.n} code ${vector.code}`;
    assert.equal(ok, vector.valid, `${label}: ${vector.valid ? 'rejected' : `accepted (${vector.reason})`}`);
    if (!ok) { invalid++; continue; }
    assert.deepEqual(grid.map(String), vector.grid, `${label}: integers`);
    assert.deepEqual(Array.from(weights.subarray(0, vector.influences), float32Hex), vector.weights, `${label}: weights`);
    valid++;
  }
  assert.ok(valid > 1000 && invalid > 100, `${valid} valid, ${invalid} invalid vectors`);
});

test('the conformance example files decode to their expected joints and weights', { skip: !vectors && 'no examples' }, () => {
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
  assert.throws(() => codecFromExtension({ ...base, n: 2 ** 60, weightBits: 60 }), /"n" = \d+ must be an integer 0..2\^53/);
  assert.throws(() => codecFromExtension({ ...base, n: '18446744073709551616', weightBits: 64 }), /"n"/);
  assert.throws(() => codecFromExtension({ ...base, n: 1063, weightBits: 11, axisSamples: [2] }), /"axisSamples" must be absent/);
});
