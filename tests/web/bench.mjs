// bench.mjs - web runtime benchmarks (ctest -L bench: web_bench; numbers go to docs/benchmarks-web.md):
//  1. CPU decode (web/src/decode.js) in vertices/s against TypedArray.set copying the bytes the
//     decoder writes (4 x u16 joints + 4 x f32 weights = 24 bytes a vertex), in node (V8).
//  2. Rendering in headless chromium on SwiftShader: many animated instances of a real mesh with
//     the plugin's GPU decode vs the same scene with float skin attributes (plain three.js on
//     the `skinpack decompress` output), frame times measured in the same page run: RE_Player
//     and Fox at the default OSS budget and Fox Fixed-coded (the cheapest decode).
// Usage: node tests/web/bench.mjs [--instances N] [--frames F] [--rounds R] (env as for the tests).
import { basename } from 'node:path';
import { allCases, WORK } from './cases.mjs';
import { readGltf, readAccessor } from './gltf_file.mjs';
import { openTestPage } from './browser.mjs';
import { codecFromExtension, decodeSkin, SKINPACK_EXTENSION } from '../../web/src/decode.js';

const args = process.argv.slice(2);
const option = (name, fallback) => { const i = args.indexOf(name); return i >= 0 ? Number(args[i + 1]) : fallback; };
const INSTANCES = option('--instances', 64), FRAMES = option('--frames', 40), ROUNDS = option('--rounds', 3);
const cases = allCases();

function median(values) { return [...values].sort((a, b) => a - b)[values.length >> 1]; }

function cpuDecodeBench(c, targetVertices = 2e6) {
  const file = readGltf(c.packed);
  const ext = file.json.meshes.flatMap((m) => m.primitives).map((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]).find(Boolean);
  const codec = codecFromExtension(ext);
  const words = readAccessor(file, ext.vertices), lut = readAccessor(file, ext.tupleTable);
  const repeat = Math.ceil(targetVertices / (words.length / codec.wordsPerVertex));
  const tiled = new Uint32Array(words.length * repeat);
  for (let r = 0; r < repeat; ++r) tiled.set(words, r * words.length);
  const vertices = tiled.length / codec.wordsPerVertex;
  const source = new Uint8Array(vertices * 24), target = new Uint8Array(vertices * 24);
  const decodeTimes = [], copyTimes = [];
  for (let run = 0; run < 5; ++run) {
    let start = performance.now();
    decodeSkin(codec, tiled, lut);
    decodeTimes.push(performance.now() - start);
    start = performance.now();
    target.set(source);
    copyTimes.push(performance.now() - start);
  }
  const decode = vertices / (median(decodeTimes) / 1000), copy = vertices / (median(copyTimes) / 1000);
  return { name: c.name, method: `${ext.method} K=${ext.influences} ${ext.weightBits}+${ext.tupleBits} bits`,
           vertices, decode, copy };
}

const rows = [];
for (const tag of ['RE_Player_female_fallback', 'Fox_fallback', 'Fox_pot20', 'Fox_any22', 'Fox_oss48', 'Fox_oss64']) {
  const c = cases.find((x) => x.name === tag);
  if (c) rows.push(cpuDecodeBench(c));
}
console.log('\n| file | codec | vertices | decode (Mvertices/s) | TypedArray.set of 24 B/vertex (Mvertices/s) | ratio |\n|---|---|---|---|---|---|');
for (const r of rows)
  console.log(`| ${r.name} | ${r.method} | ${r.vertices.toLocaleString('en')} | ${(r.decode / 1e6).toFixed(1)} | ${(r.copy / 1e6).toFixed(0)} | ${(r.decode / r.copy).toFixed(3)} |`);

const SCENES = ['float attributes (decompressed, plain three.js)', 'plugin GPU decode', 'plugin CPU decode'];

// Frame times of the three scenes of one case, ROUNDS interleaved rounds (against the drift of
// a shared machine); returns the median of each scene's round medians and renderer.info.
async function renderBench(page, c) {
  const variants = [[basename(c.decoded), null], [basename(c.packed), 'gpu'], [basename(c.packed), 'cpu']];
  const results = variants.map(() => []);
  let info = null;
  for (let round = 0; round < ROUNDS; ++round)
    for (let v = 0; v < variants.length; ++v) {
      const r = await page.page.evaluate(([f, d, n, k]) => window.skinpackTest.benchmark(f, d, n, k), [`/files/${variants[v][0]}`, variants[v][1], INSTANCES, FRAMES]);
      results[v].push(r.median);
      info = r.info;
    }
  const codec = codecFromExtension(readGltf(c.packed).json.meshes.flatMap((m) => m.primitives)
    .map((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]).find(Boolean));
  return { name: c.name, codec: `${codec.method} ${codec.weightBits}+${codec.tupleBits} bits`, info, rounds: results, times: results.map(median) };
}

const page = await openTestPage(WORK);
const benches = [];
try {
  for (const tag of ['RE_Player_female_fallback', 'Fox_fallback', 'Fox_fixed24']) {
    const c = cases.find((x) => x.name === tag);
    if (c) benches.push(await renderBench(page, c));
  }
} finally {
  await page.close();
}
console.log(`\n${INSTANCES} instances, 256 x 256, median frame time (ms) of ${FRAMES} frames, median of ${ROUNDS} interleaved rounds`);
console.log(`| scene | ${benches.map((b) => `${b.name} (${b.codec}; ${b.info.calls} draws, ${b.info.triangles.toLocaleString('en')} triangles) | ratio`).join(' | ')} |`);
console.log(`|---|${benches.map(() => '---|---|').join('')}`);
SCENES.forEach((scene, i) => console.log(`| ${scene} | ${benches.map((b) => `${b.times[i].toFixed(1)} | ${(b.times[i] / b.times[0]).toFixed(3)}`).join(' | ')} |`));
for (const b of benches) console.log(`# ${b.name} rounds (ms): ${SCENES.map((s, i) => b.rounds[i].map((t) => t.toFixed(1)).join('/')).join('  ')}`);
