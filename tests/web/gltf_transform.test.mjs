// gltf_transform.test.mjs - SkinpackPackedSkin (web/gltf-transform) through glTF-Transform:
// after copy, prune, dedup, weld, reorder and the CLI's optimize without simplify (with
// --config), each file still decodes (`skinpack decompress`, the ground truth) to the same skin
// per vertex, matched by position; an edit that breaks the skin makes the write refuse.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { allCases, CLI, fallbackBufferLayout, WORK } from './cases.mjs';
import { readGltf, readAccessor } from './gltf_file.mjs';
import { core, functions, MeshoptEncoder } from './web_modules.mjs';
import { SkinpackPackedSkin, WORDS_ATTRIBUTE } from '../../web/gltf-transform/SkinpackPackedSkin.js';
import { compactLayout, SKINPACK_EXTENSION } from '../../web/src/decode.js';

const ROOT = fileURLToPath(new URL('../../', import.meta.url));
const GLTF_TRANSFORM_CLI = join(ROOT, 'tools/node_modules/.bin/gltf-transform');
const CONFIG = join(ROOT, 'web/gltf-transform/config.mjs');
const io = new core.NodeIO().registerExtensions([SkinpackPackedSkin]);
await MeshoptEncoder.ready;

// position (float bits) -> set of skins (joint:weight bits x 4) of every vertex there.
function skinsByPosition(decodedPath) {
  const file = readGltf(decodedPath), map = new Map();
  let vertices = 0;
  file.json.meshes.forEach((mesh) => mesh.primitives.forEach((primitive) => {
    if (primitive.attributes.JOINTS_0 === undefined) return;
    const position = new Uint32Array(readAccessor(file, primitive.attributes.POSITION).buffer);
    const joints = readAccessor(file, primitive.attributes.JOINTS_0);
    const weights = new Uint32Array(readAccessor(file, primitive.attributes.WEIGHTS_0).buffer);
    for (let v = 0; v < joints.length / 4; ++v, ++vertices) {
      const key = `${position[3 * v]},${position[3 * v + 1]},${position[3 * v + 2]}`;
      let skin = '';
      for (let s = 0; s < 4; ++s) skin += `${joints[4 * v + s]}:${weights[4 * v + s]} `;
      if (!map.has(key)) map.set(key, new Set());
      map.get(key).add(skin);
    }
  }));
  return { map, vertices };
}

function assertSameSkins(reference, outputPath, label) {
  const decoded = `${outputPath.slice(0, -4)}_decoded.glb`;
  execFileSync(CLI, ['decompress', outputPath, '-o', decoded], { stdio: ['ignore', 'ignore', 'pipe'] });
  const ours = skinsByPosition(decoded), theirs = skinsByPosition(reference);
  assert.ok(ours.vertices > 0, `${label}: no skinned vertex`);
  for (const [position, skins] of ours.map) {
    const expected = theirs.map.get(position);
    assert.ok(expected, `${label}: vertex at ${position} is not in the original`);
    for (const skin of skins) assert.ok(expected.has(skin), `${label}: vertex at ${position} has skin ${skin}, original ${[...expected].join(' | ')}`);
  }
  return ours.vertices;
}

function packedState(path) {
  const { json } = readGltf(path);
  const primitive = json.meshes.flatMap((m) => m.primitives).find((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]);
  assert.ok(primitive, `${path}: the extension was dropped`);
  assert.equal(primitive.attributes[WORDS_ATTRIBUTE], undefined, 'the in-memory words attribute leaked into the file');
  const words = json.accessors[primitive.extensions[SKINPACK_EXTENSION].vertices];
  assert.equal(json.bufferViews[words.bufferView].target, undefined, 'the words bufferView has a target');
  // Compact files are written in the fallback-buffer layout only (a loader without the extension must refuse them).
  const layout = compactLayout(json, primitive);
  assert.ok(layout === null || layout === 'fallback-buffer', `${path}: compact placeholders in the ${layout} layout`);
  return { compact: layout === 'fallback-buffer', required: (json.extensionsRequired || []).includes(SKINPACK_EXTENSION) };
}

function firstWords(path) {
  const file = readGltf(path);
  const primitive = file.json.meshes.flatMap((m) => m.primitives).find((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]);
  return readAccessor(file, primitive.extensions[SKINPACK_EXTENSION].vertices);
}

function wordsUnchanged(a, b) {
  const x = firstWords(a), y = firstWords(b);
  return x.length === y.length && x.every((w, i) => w === y[i]);
}

const OPERATIONS = {
  copy: [],
  prune: [functions.prune()],
  dedup: [functions.dedup()],
  weld: [functions.weld()],
  reorder: [functions.weld(), functions.reorder({ encoder: MeshoptEncoder })], // reorder skips unwelded primitives
};

const cases = allCases().filter((c) => /_(fallback|compact)$/.test(c.name));
for (const c of cases) {
  for (const [name, transforms] of Object.entries(OPERATIONS)) {
    test(`${c.name}: ${name} keeps the skin of every vertex`, async () => {
      const document = await io.read(c.packed);
      await document.transform(...transforms);
      const out = join(WORK, `${c.name}_gt_${name}.glb`);
      await io.write(out, document);
      const state = packedState(out);
      assert.equal(state.compact, c.name.endsWith('_compact'), 'the mode changed');
      assert.equal(state.required, state.compact, 'extensionsRequired does not match the mode');
      const vertices = assertSameSkins(c.decoded, out, `${c.name} ${name}`);
      console.log(`# ${c.name} ${name}: ${vertices} vertices (original ${skinsByPosition(c.decoded).vertices}), words in order: ${wordsUnchanged(c.packed, out)}`);
    });
  }
  test(`${c.name}: gltf-transform optimize --config (no simplify) keeps the skin of every vertex`, { skip: !existsSync(GLTF_TRANSFORM_CLI) && 'tools/ not installed' }, () => {
    const out = join(WORK, `${c.name}_gt_optimize.glb`);
    execFileSync(GLTF_TRANSFORM_CLI, ['optimize', c.packed, out, '--config', CONFIG, '--simplify', 'false',
      '--compress', 'false', '--texture-compress', 'false'], { stdio: ['ignore', 'ignore', 'pipe'] });
    assert.equal(packedState(out).compact, c.name.endsWith('_compact'));
    assertSameSkins(c.decoded, out, `${c.name} optimize`);
  });
}

test('compact files in the fallback-buffer layout: read, welded, written compact with the same skins', async () => {
  const fox = cases.find((c) => c.name === 'Fox_compact');
  const input = join(WORK, 'Fox_compact_fallback_buffer_gt.glb');
  fallbackBufferLayout(fox.packed, input);
  const document = await io.read(input);
  await document.transform(functions.weld());
  const out = join(WORK, 'Fox_compact_fallback_buffer_gt_weld.glb');
  await io.write(out, document);
  assert.deepEqual(packedState(out), { compact: true, required: true });
  assert.ok(assertSameSkins(fox.decoded, out, 'fallback-buffer weld') < 1728, 'weld merged nothing');
});

test('a write whose words no longer match the vertices is refused, naming mesh and primitive', async () => {
  const fox = cases.find((c) => c.name === 'Fox_fallback');
  const document = await io.read(fox.packed);
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  const words = primitive.getAttribute(WORDS_ATTRIBUTE);
  words.setArray(words.getArray().slice(0, -1)); // one vertex short
  await assert.rejects(io.writeBinary(document), /SKINPACK_packed_skin: mesh 0 "fox1" primitive 0: vertices: 1727 packed vertices, the primitive has 1728$/);
  words.setArray(new Uint32Array(1728).fill(0xffffffff));
  await assert.rejects(io.writeBinary(document), /mesh 0 "fox1" primitive 0: vertices: .* at vertex 0$/);
});
