// meshopt_unpack.mjs - writes a GLB's EXT_meshopt_compression bufferViews out decoded, with the
// npm meshoptimizer decoder (independent of skinpack's libmeshoptimizer path): the tests' plain
// reference for gltfpack -c/-cc files (and skinpack compress --meshopt). Every view with data is
// copied into one new BIN chunk; views of other data-less buffers (skinpack's compact fallback
// buffer) stay data-less.
//   node tools/meshopt_unpack.mjs IN.glb OUT.glb
import { readFileSync, writeFileSync } from 'node:fs';
import { MeshoptDecoder } from 'meshoptimizer';

const [input, output] = process.argv.slice(2);
if (!input || !output) {
  console.error('usage: node tools/meshopt_unpack.mjs IN.glb OUT.glb');
  process.exit(2);
}
const file = readFileSync(input);
const jsonLength = file.readUInt32LE(12);
const json = JSON.parse(file.subarray(20, 20 + jsonLength).toString('utf8'));
const binStart = 20 + jsonLength;
const bin = file.subarray(binStart + 8, binStart + 8 + file.readUInt32LE(binStart));
if (json.buffers.some((b, i) => i > 0 && b.uri === undefined && !b.extensions)) throw new Error('unexpected buffer');
const source = (index) => {
  if (index !== 0) throw new Error(`${input}: only buffer 0 (the BIN chunk) may hold data here`);
  return bin;
};

await MeshoptDecoder.ready;
const NAMES = ['EXT_meshopt_compression', 'KHR_meshopt_compression'];
const pieces = [];
const kept = new Map(); // data-less buffer -> its index in the output
const buffers = json.buffers;
let size = 0;
for (const view of json.bufferViews) {
  const name = NAMES.find((n) => view.extensions && view.extensions[n]);
  let bytes;
  if (!name && view.buffer > 0 && buffers[view.buffer].uri === undefined) {
    if (!kept.has(view.buffer)) kept.set(view.buffer, kept.size + 1);
    view.buffer = kept.get(view.buffer);
    continue;
  } else if (name) {
    const ext = view.extensions[name];
    bytes = new Uint8Array(ext.count * ext.byteStride);
    const data = source(ext.buffer).subarray(ext.byteOffset ?? 0, (ext.byteOffset ?? 0) + ext.byteLength);
    MeshoptDecoder.decodeGltfBuffer(bytes, ext.count, ext.byteStride, data, ext.mode, ext.filter ?? 'NONE');
    delete view.extensions[name];
    if (Object.keys(view.extensions).length === 0) delete view.extensions;
  } else {
    const offset = view.byteOffset ?? 0;
    bytes = source(view.buffer).subarray(offset, offset + view.byteLength);
  }
  size = (size + 3) & ~3;
  view.buffer = 0;
  view.byteOffset = size;
  view.byteLength = bytes.length;
  pieces.push([size, bytes]);
  size += bytes.length;
}
size = (size + 3) & ~3;
const out = new Uint8Array(size);
for (const [offset, bytes] of pieces) out.set(bytes, offset);
json.buffers = [{ byteLength: size }, ...[...kept.keys()].map((b) => buffers[b])];
for (const key of ['extensionsUsed', 'extensionsRequired']) {
  if (!json[key]) continue;
  json[key] = json[key].filter((n) => !NAMES.includes(n));
  if (json[key].length === 0) delete json[key];
}
let text = Buffer.from(JSON.stringify(json));
text = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
const header = Buffer.alloc(20);
header.writeUInt32LE(0x46546c67, 0);
header.writeUInt32LE(2, 4);
header.writeUInt32LE(20 + text.length + 8 + out.length, 8);
header.writeUInt32LE(text.length, 12);
header.writeUInt32LE(0x4e4f534a, 16);
const chunk = Buffer.alloc(8);
chunk.writeUInt32LE(out.length, 0);
chunk.writeUInt32LE(0x004e4942, 4);
writeFileSync(output, Buffer.concat([header, text, chunk, Buffer.from(out)]));
