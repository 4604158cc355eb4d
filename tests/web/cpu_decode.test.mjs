// cpu_decode.test.mjs - web/src/decode.js against `skinpack decompress`, bit for bit, on every
// case of cases.mjs; and its refusals of broken data.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readGltf, readAccessor } from './gltf_file.mjs';
import { allCases, ASSETS } from './cases.mjs';
import { codecFromExtension, decodeSkin, SKINPACK_EXTENSION } from '../../web/src/decode.js';

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
