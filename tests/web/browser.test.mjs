// browser.test.mjs - SkinpackGLTFPlugin in headless Chromium (WebGL2 on SwiftShader):
//  * every case of cases.mjs, GPU and CPU decode, against plain three.js rendering the
//    `skinpack decompress` output of the same file (must be pixel-identical up to rasteriser
//    noise) and against the uncompressed original (a few pixels may differ: see ORIGINAL_*);
//  * the shader's decode of every GPU-profile case read back from an integer render target;
//  * compact files in the fallback-buffer layout: rejected by three.js without the plugin;
//  * broken extension data: rejected, naming the mesh and primitive.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { copyFileSync, writeFileSync } from 'node:fs';
import { basename, join } from 'node:path';
import { allCases, fallbackBufferLayout, WORK } from './cases.mjs';
import { openTestPage, compareImages } from './browser.mjs';
import { readAccessor, readGltf, writeGlb } from './gltf_file.mjs';
import { SKINPACK_EXTENSION } from '../../web/src/decode.js';
import { gpuProfileRefusal } from '../../web/src/gpu.js';
import { readVectors } from './conformance.mjs';

// A channel difference of up to 2/255 is rasteriser noise (SwiftShader's float rounding of the
// skinned positions); against the decompressed file nothing else may differ.
const NOISE = 2;
const DECODED_MAX_PIXELS = 0;
// Against the original the weights differ by up to maxError (1.5e-4 to 5.2e-4 at 32 bits a
// vertex) and the original may have more than 4 influences, which three.js ignores but the
// compressor renormalises: a skinned position moves by at most maxError times the joint
// offsets, a fraction of a pixel at 256 x 256, so only silhouette pixels can flip between mesh
// and background (a large channel difference) while shading inside changes by less than
// 16/255. At most 16 of the 65536 pixels may differ by more than that (measured: 0 to 3).
const ORIGINAL_TOLERANCE = 16;
const ORIGINAL_MAX_PIXELS = 16;
const FOX_TIMES = [0.4, 1.2, 2.0, 3.1];
const STILL_TIMES = [0.5, 1.5];

const cases = allCases();
let page;
before(async () => { page = await openTestPage(WORK); });
after(async () => { if (page) await page.close(); });

function render(file, decode, times) {
  return page.page.evaluate(([f, d, t]) => window.skinpackTest.render(f, d, t), [`/files/${basename(file)}`, decode, times]);
}

const references = new Map();
async function reference(file, times) {
  if (!references.has(file)) references.set(file, await render(file, null, times));
  return references.get(file);
}

function originalCopy(source) {
  const copy = join(WORK, `${basename(source, '.glb')}_original.glb`);
  copyFileSync(source, copy);
  return copy;
}

const narrowTags = new Set();
for (const c of cases) {
  const times = basename(c.source) === 'Fox.glb' ? FOX_TIMES : STILL_TIMES;
  const atOriginalBudget = /_(fallback|compact)$/.test(c.name);
  for (const decode of ['gpu', 'cpu']) {
    test(`${c.name} ${decode}: renders like plain three.js on the decompressed file${atOriginalBudget ? ' and the original' : ''}`, async () => {
      const result = await render(c.packed, decode, times);
      assert.ok(result.modes.length > 0, 'no mesh decoded by the plugin');
      if (decode === 'cpu') assert.ok(result.modes.every((m) => m === 'cpu'), result.modes.join());
      if (decode === 'gpu' && result.modes.every((m) => m === 'gpu')) narrowTags.add(c.name);
      const decoded = await reference(c.decoded, times);
      const original = atOriginalBudget ? await reference(originalCopy(c.source), times) : null;
      result.images.forEach((image, i) => {
        const d = compareImages(decoded.images[i], image, NOISE);
        assert.ok(d.differing <= DECODED_MAX_PIXELS, `t = ${times[i]}: ${d.differing} pixels differ from the decompressed file (max delta ${d.maxDelta})`);
        if (!original) return;
        const o = compareImages(original.images[i], image, ORIGINAL_TOLERANCE);
        assert.ok(o.differing <= ORIGINAL_MAX_PIXELS,
                  `t = ${times[i]}: ${o.differing} of ${o.pixels} pixels differ from the original by more than ${ORIGINAL_TOLERANCE}/255`);
        console.log(`# ${c.name} ${decode} t=${times[i]}: vs decompressed ${d.differing} px (max delta ${d.maxDelta}), vs original ${o.differing} px > ${ORIGINAL_TOLERANCE}`);
      });
    });
  }
}

test('a SkeletonUtils clone of a GPU-decoded scene renders the same (shadows, bounds, raycasts stay on the packed skin)', async () => {
  const fox = cases.find((c) => c.name === 'Fox_compact');
  const cloned = await page.page.evaluate(([f, t]) => window.skinpackTest.render(f, 'gpu', t, true), [`/files/${basename(fox.packed)}`, FOX_TIMES]);
  const decoded = await reference(fox.decoded, FOX_TIMES);
  assert.deepEqual(cloned.modes, ['gpu']);
  cloned.images.forEach((image, i) => assert.equal(compareImages(decoded.images[i], image, NOISE).differing, 0, `t = ${FOX_TIMES[i]}`));
});

// A morph target (a stretch along y) on Fox's skinned primitive, the same edit on the packed and
// on the decompressed file: morphing and skinning together on both paths.
function withMorphTarget(path, out) {
  const { json, buffers } = readGltf(path);
  const primitive = json.meshes[0].primitives[0];
  const positions = readAccessor({ json, buffers }, primitive.attributes.POSITION);
  const deltas = new Float32Array(positions.length);
  for (let v = 0; v < positions.length; v += 3) deltas[v + 1] = 0.4 * positions[v + 1];
  const bin = new Uint8Array(((buffers[0].length + 3) & ~3) + deltas.byteLength);
  bin.set(buffers[0]);
  bin.set(new Uint8Array(deltas.buffer), bin.length - deltas.byteLength);
  json.bufferViews.push({ buffer: 0, byteOffset: bin.length - deltas.byteLength, byteLength: deltas.byteLength });
  json.accessors.push({ bufferView: json.bufferViews.length - 1, componentType: 5126, count: deltas.length / 3, type: 'VEC3' });
  primitive.targets = [{ POSITION: json.accessors.length - 1 }];
  json.meshes[0].weights = [0];
  json.buffers[0].byteLength = bin.length;
  writeGlb(out, json, bin);
  return out;
}

test('a skinned primitive with a morph target renders the same on both paths (morphing and skinning)', async () => {
  const fox = cases.find((c) => c.name === 'Fox_fallback');
  const packed = withMorphTarget(fox.packed, join(WORK, 'Fox_morph.glb'));
  const decoded = withMorphTarget(fox.decoded, join(WORK, 'Fox_morph_decoded.glb'));
  const reference = await render(decoded, null, FOX_TIMES), unmorphed = await render(fox.decoded, null, FOX_TIMES);
  assert.ok(compareImages(reference.images[0], unmorphed.images[0], NOISE).differing > 200, 'the morph target changes nothing');
  for (const decode of ['gpu', 'cpu']) {
    const result = await render(packed, decode, FOX_TIMES);
    assert.ok(result.skinnedMorphs > 0);
    result.images.forEach((image, i) => assert.equal(compareImages(reference.images[i], image, NOISE).differing, 0, `${decode} t = ${FOX_TIMES[i]}`));
  }
});

test('the GPU path covers the 32-bit profile and hands wider codecs to the CPU', () => {
  for (const tag of ['Fox_fallback', 'Fox_compact', 'Fox_fixed24', 'Fox_cube21', 'Fox_pot20', 'Fox_any22', 'Fox_k1', 'Fox_k2', 'Fox_k3'])
    assert.ok(narrowTags.has(tag), `${tag} did not decode on the GPU`);
  for (const tag of ['Fox_oss48', 'Fox_oss64', 'Fox_fixed64', 'Fox_any64'])
    assert.ok(!narrowTags.has(tag), `${tag} claims GPU decode beyond 32 bits`);
});

test('the WebGL2 shader decodes every GPU-profile case exactly (integer render target)', async () => {
  let checked = 0;
  for (const c of cases) {
    if (!narrowTags.has(c.name)) continue;
    // Tuple textures of 8 entries a row (a power of two, as the shader requires): every table spans rows (the plugin uses 2048).
    const results = await page.page.evaluate((f) => window.skinpackTest.gpuReadback(f, 8), `/files/${basename(c.packed)}`);
    for (const r of results) {
      assert.equal(r.jointMismatches, 0, `${c.name} ${r.mesh}: joints differ, first ${JSON.stringify(r.first)}`);
      assert.equal(r.qMismatches, 0, `${c.name} ${r.mesh}: grid integers differ`);
      // Any computes w1 = 1 - sum in float on the GPU (double in C): a few ulp.
      assert.ok(r.method === 'any' ? r.maxUlp <= 4 : r.weightMismatches === 0,
                `${c.name} ${r.mesh}: ${r.weightMismatches} weights differ (max ${r.maxUlp} ulp)`);
      checked += r.vertexCount;
    }
  }
  assert.ok(checked > 0);
});

const vectors = readVectors();
test('every conformance vector of the 32-bit GPU profile decodes exactly in the WebGL2 shader', { skip: !vectors && 'no docs/extension/conformance' }, async () => {
  const groups = new Map();
  let outside = 0;
  for (const { vector, ext, codec } of vectors) {
    if (!vector.valid) continue; // rejecting codes is a load-time (CPU) step, spec 1.0
    if (gpuProfileRefusal(codec)) { outside++; continue; }
    const key = JSON.stringify(ext);
    if (!groups.has(key)) groups.set(key, { ext, codes: [], grids: [], weights: [] });
    const group = groups.get(key);
    group.codes.push(vector.code);
    group.grids.push(vector.grid.map(Number));
    group.weights.push(vector.weights);
  }
  const result = await page.page.evaluate((g) => window.skinpackTest.gpuConformance(g), [...groups.values()]);
  console.log(`# GPU conformance: ${result.total} weights of ${groups.size} codecs, ${result.exactWeights} bit-exact, ` +
              `max |dw| ${result.maxWeightError}; ${outside} valid vectors outside the 32-bit profile (CPU path)`);
  assert.equal(result.mismatchCount, 0, result.mismatches.join('\n'));
  assert.ok(result.maxWeightError <= 1e-6, `weights off by ${result.maxWeightError}`);
  assert.ok(result.total > 500);
});

// ---- compact files without the plugin, broken files with it --------------------------------

test('compact files: plain three.js rejects the fallback-buffer layout; the plugin renders it', async () => {
  const fox = cases.find((c) => c.name === 'Fox_compact');
  const file = join(WORK, 'Fox_compact_fallback_buffer.glb');
  fallbackBufferLayout(fox.packed, file);
  const url = `/files/${basename(file)}`;
  const refusal = await page.page.evaluate((f) => window.skinpackTest.loadError(f, null), url);
  // three.js has no data for the marked buffer (no uri, not the GLB chunk) and fails the load.
  assert.ok(refusal, 'three.js without the plugin loaded a compact file');
  assert.doesNotMatch(refusal, /SkinpackGLTFPlugin/);
  for (const decode of ['gpu', 'cpu']) {
    const ours = await render(file, decode, FOX_TIMES), decoded = await reference(fox.decoded, FOX_TIMES);
    ours.images.forEach((image, i) => assert.equal(compareImages(decoded.images[i], image, NOISE).differing, 0));
  }
});

test('compact files as the CLI writes them: plain three.js never shows the skin (rejects, or today: every vertex on joint 0)', async () => {
  const fox = cases.find((c) => c.name === 'Fox_compact');
  const { json } = readGltf(fox.packed);
  const joints = json.accessors[json.meshes[0].primitives[0].attributes.JOINTS_0];
  const result = await page.page.evaluate((f) => window.skinpackTest.plainSkinWeights(f), `/files/${basename(fox.packed)}`);
  if (joints.bufferView === undefined) {
    // three.js r187 only warns about the unknown required extension, loads data-less accessors
    // as zeros and normalises the zero weights to (1, 0, 0, 0): every vertex follows joint 0
    // rigidly (what issue 10's fallback-buffer layout turns into a refusal).
    assert.equal(result.error, undefined);
    assert.deepEqual(result.weights, ['1,0,0,0']);
    assert.equal(result.maxJoint, 0);
    assert.ok(page.log.some((line) => /Unknown extension "SKINPACK_packed_skin"/.test(line)), 'no warning');
  } else {
    assert.ok(result.error, 'plain three.js loaded a compact file');
  }
});

function brokenVariant(name, edit) {
  const fox = cases.find((c) => c.name === 'Fox_fallback');
  const { json, buffers } = readGltf(fox.packed);
  const bin = buffers[0].slice();
  edit(json, bin);
  const file = join(WORK, `Fox_broken_${name}.glb`);
  writeGlb(file, json, bin);
  return `/files/${basename(file)}`;
}

const extOf = (json) => json.meshes[0].primitives[0].extensions[SKINPACK_EXTENSION];
const BROKEN = {
  weightBits: [(json) => { extOf(json).weightBits += 1; }, /: weightBits: \d+ contradicts the other parameters or the data \(expected \d+\)$/],
  method: [(json) => { extOf(json).method = 'zip'; }, /: method: unknown method$/],
  jointCount: [(json) => { extOf(json).jointCount = json.skins[0].joints.length + 1; }, /: jointCount: \d+ contradicts the other parameters or the data \(expected \d+\)$/],
  tableType: [(json) => { json.accessors[extOf(json).tupleTable].componentType = 5123; }, /: (tupleTable: 2 contradicts|"tupleTable" accessor \d+ ends at byte)/],
  wordCount: [(json) => { json.accessors[extOf(json).vertices].count -= 1; }, /: vertices: \d+ packed vertices, the primitive has \d+$/],
  word: [(json, bin) => {
    const view = json.bufferViews[json.accessors[extOf(json).vertices].bufferView];
    new DataView(bin.buffer, bin.byteOffset).setUint32((view.byteOffset || 0) + 7 * 4, 0xffffffff, true);
  }, /: vertices: .* at vertex 7$/],
  sharedWords: [(json) => {
    const primitive = json.meshes[0].primitives[0];
    const copy = JSON.parse(JSON.stringify(primitive));
    copy.extensions[SKINPACK_EXTENSION].jointCount -= 1;
    json.meshes.push({ name: 'fox1', primitives: [copy] });
  }, /shares "vertices" accessor \d+ with mesh 0 "fox1" primitive 0 but declares different properties/, 'mesh 1 "fox1" primitive 0'],
  sharedWordsOtherTable: [(json) => {
    const primitive = json.meshes[0].primitives[0];
    const copy = JSON.parse(JSON.stringify(primitive));
    json.accessors.push({ ...json.accessors[extOf(json).tupleTable] });
    copy.extensions[SKINPACK_EXTENSION].tupleTable = json.accessors.length - 1;
    json.meshes.push({ name: 'fox1', primitives: [copy] });
  }, /shares "vertices" accessor \d+ with mesh 0 "fox1" primitive 0 but declares another "tupleTable"/, 'mesh 1 "fox1" primitive 0'],
  wordsRange: [(json) => { json.accessors[extOf(json).vertices].byteOffset = 8; }, /"vertices" accessor \d+ ends at byte \d+, past its bufferView/],
  sparse: [(json) => { json.accessors[extOf(json).tupleTable].normalized = true; }, /"tupleTable" accessor \d+ must be neither sparse nor normalized/],
  tableEntry: [(json, bin) => {
    const accessor = json.accessors[extOf(json).tupleTable];
    bin[(json.bufferViews[accessor.bufferView].byteOffset || 0) + 1] = extOf(json).jointCount;
  }, /: tupleTable: joint \d+ not below jointCount \d+ at tuple 0$/],
};

for (const [name, [edit, pattern, where = 'mesh 0 "fox1" primitive 0']] of Object.entries(BROKEN)) {
  test(`broken ${name}: the load is rejected naming mesh and primitive`, async () => {
    const url = brokenVariant(name, edit);
    for (const decode of ['gpu', 'cpu']) {
      const message = await page.page.evaluate(([f, d]) => window.skinpackTest.loadError(f, d), [url, decode]);
      assert.ok(message, `${decode}: a broken file loaded`);
      assert.ok(message.startsWith(`SkinpackGLTFPlugin: ${where}: `), message);
      assert.match(message, pattern);
    }
  });
}
