// meshopt.test.mjs - files of `skinpack compress --meshopt` (packed words, and the tuple table
// when it pays, in EXT_meshopt_compression views) through the web runtimes:
//  * three.js GLTFLoader with SkinpackGLTFPlugin in headless Chromium: with
//    loader.setMeshoptDecoder(MeshoptDecoder) (three/addons/libs/meshopt_decoder.module.js) the
//    plugin reads the words through the parser, so GPU and CPU decode get exactly the words and
//    skin of the same file without --meshopt; without the decoder the load is rejected; the
//    viewer (web/viewer) sets the decoder and opens them;
//  * glTF-Transform with EXTMeshoptCompression registered beside SkinpackPackedSkin: read,
//    written and decompressed again, every vertex keeps its skin; without it the read is refused.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { basename, join } from 'node:path';
import { ASSETS, CLI, makeCase, WORK } from './cases.mjs';
import { readAccessor, readGltf } from './gltf_file.mjs';
import { core } from './web_modules.mjs';
import { SkinpackPackedSkin } from '../../web/gltf-transform/SkinpackPackedSkin.js';
import { SKINPACK_EXTENSION } from '../../web/src/decode.js';

const base = new URL('../../web/node_modules/', import.meta.url);
const { EXTMeshoptCompression } = await import(new URL('@gltf-transform/extensions/dist/index.js', base));
const { MeshoptDecoder, MeshoptEncoder } = await import(new URL('meshoptimizer/index.js', base));

const fox = ASSETS.find((a) => basename(a) === 'Fox.glb');
const MODES = ['compact', 'fallback'];
// Per mode: the --meshopt file and the same compression without it (the reference).
const cases = Object.fromEntries(MODES.map((mode) => [mode, {
  meshopt: makeCase(fox, `${mode}_meshopt`, [`--${mode}`, '--meshopt']),
  plain: makeCase(fox, mode, [`--${mode}`]),
}]));

function packedPrimitive(json) {
  return json.meshes.flatMap((m) => m.primitives).find((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]);
}

test('the --meshopt files have their packed words in a required EXT_meshopt_compression view', () => {
  for (const mode of MODES) {
    const { json } = readGltf(cases[mode].meshopt.packed);
    const words = json.accessors[packedPrimitive(json).extensions[SKINPACK_EXTENSION].vertices];
    assert.ok(json.bufferViews[words.bufferView].extensions.EXT_meshopt_compression, `${mode}: words not meshopt-compressed`);
    assert.ok(json.extensionsRequired.includes('EXT_meshopt_compression'), `${mode}: meshopt not required`);
  }
});

// ---- three.js in Chromium ----------------------------------------------------------------

let page = null;
const CHROMIUM = process.env.SKINPACK_CHROMIUM;
before(async () => {
  if (!CHROMIUM) return;
  const { openTestPage } = await import('./browser.mjs');
  page = await openTestPage(WORK);
});
after(async () => { if (page) await page.close(); });

// In the page: loads url with the plugin (decode 'gpu' or 'cpu'), with or without the meshopt
// decoder; returns the load error or, per plugin-decoded mesh, its words and decoded skin.
async function loadInPage(url, decode, withDecoder) {
  return page.page.evaluate(async ([u, d, m]) => {
    const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');
    const { MeshoptDecoder } = await import('three/addons/libs/meshopt_decoder.module.js');
    const { SkinpackGLTFPlugin, skinpackData } = await import('/src/SkinpackGLTFPlugin.js');
    const loader = new GLTFLoader();
    if (m) loader.setMeshoptDecoder(MeshoptDecoder);
    loader.register((parser) => new SkinpackGLTFPlugin(parser, { decode: d }));
    try {
      const gltf = await loader.loadAsync(u);
      const meshes = [];
      gltf.scene.traverse((o) => {
        const data = o.isSkinnedMesh && skinpackData(o);
        if (data) meshes.push({ decode: o.userData.skinpack.decode, words: Array.from(data.words),
          joints: Array.from(data.decoded.joints), weights: Array.from(data.decoded.weights) });
      });
      return { meshes };
    } catch (error) {
      return { error: String(error && error.message ? error.message : error) };
    }
  }, [url, decode, withDecoder]);
}

for (const mode of MODES) {
  for (const decode of ['gpu', 'cpu']) {
    test(`three.js + SkinpackGLTFPlugin (${decode}) with setMeshoptDecoder: ${mode} --meshopt file has the words and skin of the file without`, { skip: !CHROMIUM && 'no chromium' }, async () => {
      const { meshopt, plain } = cases[mode];
      const result = await loadInPage(`/files/${basename(meshopt.packed)}`, decode, true);
      assert.equal(result.error, undefined, result.error);
      assert.equal(result.meshes.length, 1);
      const [mesh] = result.meshes;
      assert.equal(mesh.decode, decode);
      const reference = readGltf(plain.packed);
      const expectedWords = readAccessor(reference, packedPrimitive(reference.json).extensions[SKINPACK_EXTENSION].vertices);
      assert.deepEqual(mesh.words, Array.from(expectedWords), 'the words differ from the file without --meshopt');
      // The ground truth: skinpack decompress of the same file (JOINTS_0 and float WEIGHTS_0, K = 4).
      const decoded = readGltf(meshopt.decoded), primitive = decoded.json.meshes[0].primitives[0];
      assert.deepEqual(mesh.joints, Array.from(readAccessor(decoded, primitive.attributes.JOINTS_0)));
      assert.deepEqual(mesh.weights, Array.from(readAccessor(decoded, primitive.attributes.WEIGHTS_0)));
    });
  }
  test(`three.js without setMeshoptDecoder rejects the ${mode} --meshopt file`, { skip: !CHROMIUM && 'no chromium' }, async () => {
    const result = await loadInPage(`/files/${basename(cases[mode].meshopt.packed)}`, 'gpu', false);
    assert.match(result.error || '', /setMeshoptDecoder/);
  });
}

test('the viewer opens --meshopt files (its loader has the meshopt decoder)', { skip: !CHROMIUM && 'no chromium' }, async () => {
  const viewer = await page.browser.newPage();
  try {
    for (const mode of MODES) {
      await viewer.goto(`${page.url}/viewer/?file=/files/${basename(cases[mode].meshopt.packed)}`);
      await viewer.waitForFunction(() => window.skinpackViewer && !document.getElementById('status').textContent.startsWith('Loading') &&
                                         document.getElementById('status').textContent !== '', null, { timeout: 60000 });
      assert.equal(await viewer.locator('#status.error').count(), 0, await viewer.locator('#status').innerText());
      assert.match(await viewer.locator('#meshes').innerText(), /GPU decode/);
    }
  } finally {
    await viewer.close();
  }
});

// ---- glTF-Transform ----------------------------------------------------------------------

// Joint:weight bits a vertex, from skinpack decompress of path.
function decodedSkins(path) {
  const decoded = `${path.slice(0, -4)}_decoded.glb`;
  execFileSync(CLI, ['decompress', path, '-o', decoded], { stdio: ['ignore', 'ignore', 'pipe'] });
  const file = readGltf(decoded), primitive = file.json.meshes[0].primitives[0];
  const joints = readAccessor(file, primitive.attributes.JOINTS_0);
  const weights = new Uint32Array(readAccessor(file, primitive.attributes.WEIGHTS_0).buffer);
  return Array.from(joints, (j, i) => `${j}:${weights[i]}`);
}

for (const mode of MODES) {
  test(`glTF-Transform with EXTMeshoptCompression: the ${mode} --meshopt file reads, writes and keeps every skin`, async () => {
    await MeshoptDecoder.ready;
    await MeshoptEncoder.ready;
    const io = new core.NodeIO().registerExtensions([EXTMeshoptCompression, SkinpackPackedSkin])
      .registerDependencies({ 'meshopt.decoder': MeshoptDecoder, 'meshopt.encoder': MeshoptEncoder });
    const { meshopt, plain } = cases[mode];
    const document = await io.read(meshopt.packed);
    const out = join(WORK, `Fox_${mode}_meshopt_gt.glb`);
    await io.write(out, document);
    const { json } = readGltf(out);
    assert.ok(packedPrimitive(json), 'the extension was dropped');
    assert.equal((json.extensionsRequired || []).includes(SKINPACK_EXTENSION), mode === 'compact');
    assert.deepEqual(decodedSkins(out), decodedSkins(plain.packed));
  });
}

test('glTF-Transform without EXTMeshoptCompression refuses a --meshopt file (required extension)', async () => {
  const io = new core.NodeIO().registerExtensions([SkinpackPackedSkin]);
  await assert.rejects(io.read(cases.fallback.meshopt.packed), /EXT_meshopt_compression/);
});
