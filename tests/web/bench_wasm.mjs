// bench_wasm.mjs - CPU decode throughput through WebAssembly (web/src/wasm.js, libskinpack built
// by native/wasm) in node (V8), measured as docs/benchmarks-web.md table 1 measures the JS path:
// the packed words of each file tiled to ~2 million vertices, decoded into 4 x u16 joints +
// 4 x f32 weights (24 bytes a vertex) against TypedArray.set copying 24 bytes a vertex, median
// of 5 runs each, interleaved. Also validation alone (what the GPU path needs before it uploads
// the words). Each rate is given in wall time (table 1's method) and in this process's CPU time
// (steadier on a shared, overloaded machine). --compare-js FILE adds the same measurement of a
// JS decoder module with table 1's API (codecFromExtension, decodeSkin), e.g. the one this
// runtime had before: `git show 8e5e771:web/src/decode.js > /tmp/js_decode.mjs`.
// Numbers go to docs/benchmarks-web.md, "WebAssembly decode".
// Usage: node tests/web/bench_wasm.mjs [--vertices N] [--compare-js FILE] (env as for the tests).
import { allCases } from './cases.mjs';
import { readAccessor, readGltf } from './gltf_file.mjs';
import { extensionParams, SKINPACK_EXTENSION } from '../../web/src/decode.js';
import { decode, validate, wasmMemoryBytes } from '../../web/src/wasm.js';

const args = process.argv.slice(2);
const option = (name) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : undefined; };
const TARGET_VERTICES = Number(option('--vertices') ?? 2e6);
const JS = option('--compare-js') ? await import(new URL(option('--compare-js'), `file://${process.cwd()}/`)) : null;
const RUNS = 5;
const cases = allCases();

function median(values) { return [...values].sort((a, b) => a - b)[values.length >> 1]; }

// Milliseconds of wall time and of this process's CPU time.
function timed(run) {
  const start = performance.now(), cpu = process.cpuUsage();
  run();
  const used = process.cpuUsage(cpu);
  return { wall: performance.now() - start, cpu: (used.user + used.system) / 1000 };
}

function tiledPrimitive(c) {
  const file = readGltf(c.packed);
  const ext = file.json.meshes.flatMap((m) => m.primitives).map((p) => p.extensions && p.extensions[SKINPACK_EXTENSION]).find(Boolean);
  const words = readAccessor(file, ext.vertices), lut = readAccessor(file, ext.tupleTable);
  const wordsPerVertex = ext.tupleBits + ext.weightBits > 32 ? 2 : 1;
  const repeat = Math.ceil(TARGET_VERTICES / (words.length / wordsPerVertex));
  const tiled = new Uint32Array(words.length * repeat);
  for (let r = 0; r < repeat; ++r) tiled.set(words, r * words.length);
  return { ext, primitive: { params: extensionParams(ext), words: tiled, wordsPerVertex, lut, lutComponents: ext.influences } };
}

function bench(c) {
  const { ext, primitive } = tiledPrimitive(c);
  const vertices = primitive.words.length / primitive.wordsPerVertex;
  const source = new Uint8Array(vertices * 24), target = new Uint8Array(vertices * 24);
  const runs = { decode: () => decode(primitive, { jointBytes: 2 }), validate: () => validate(primitive), copy: () => target.set(source) };
  if (JS) {
    const codec = JS.codecFromExtension(ext);
    runs.js = () => JS.decodeSkin(codec, primitive.words, primitive.lut);
  }
  const times = Object.fromEntries(Object.keys(runs).map((key) => [key, []]));
  for (let run = 0; run < RUNS; ++run) for (const key of Object.keys(runs)) times[key].push(timed(runs[key]));
  const rates = (clock) => Object.fromEntries(Object.entries(times).map(([key, list]) => [key, vertices / (median(list.map((t) => t[clock])) / 1000)]));
  return { name: c.name, codec: `${ext.method} K=${ext.influences} ${ext.weightBits}+${ext.tupleBits} bits`, vertices,
           wall: rates('wall'), cpu: rates('cpu') };
}

const rows = [];
for (const tag of ['RE_Player_female_fallback', 'Fox_fallback', 'Fox_pot20', 'Fox_any22', 'Fox_oss48', 'Fox_oss64']) {
  const c = cases.find((x) => x.name === tag);
  if (c) rows.push(bench(c));
}
const M = (rate) => (rate / 1e6).toFixed(1);
console.log(`\nnode ${process.version}, WebAssembly memory after the runs: ${(wasmMemoryBytes() / 2 ** 20).toFixed(0)} MiB; ` +
            'rates in M vertices/s, wall time / CPU time');
console.log(`| file | codec | vertices | WASM decode | WASM validate only | ${JS ? 'JS decode (--compare-js) | ' : ''}` +
            'TypedArray.set of 24 B/vertex | WASM decode / copy |');
console.log(`|---|---|---|---|---|${JS ? '---|' : ''}---|---|`);
for (const r of rows) {
  const pair = (key) => `${M(r.wall[key])} / ${M(r.cpu[key])}`;
  console.log(`| ${r.name} | ${r.codec} | ${r.vertices.toLocaleString('en')} | ${pair('decode')} | ${pair('validate')} | ` +
              `${JS ? `${pair('js')} | ` : ''}${(r.wall.copy / 1e6).toFixed(0)} / ${(r.cpu.copy / 1e6).toFixed(0)} | ` +
              `${(r.wall.decode / r.wall.copy).toFixed(3)} / ${(r.cpu.decode / r.cpu.copy).toFixed(3)} |`);
}
