// gltf_file.mjs - a minimal .glb/.gltf reader and writer for the web tests: JSON plus buffers,
// accessors as typed arrays. Only what the tests need (no sparse accessors, no data: URIs).
import { readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';

const COMPONENTS = { 5120: Int8Array, 5121: Uint8Array, 5122: Int16Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };
const SIZES = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };

export function readGltf(path) {
  const bytes = readFileSync(path);
  if (bytes.readUInt32LE(0) !== 0x46546c67) {
    const json = JSON.parse(bytes.toString('utf8'));
    const buffers = (json.buffers || []).map((b) => (b.uri ? new Uint8Array(readFileSync(join(dirname(path), b.uri))) : null));
    return { json, buffers };
  }
  let offset = 12, json = null, bin = null;
  while (offset < bytes.length) {
    const length = bytes.readUInt32LE(offset), type = bytes.readUInt32LE(offset + 4);
    const chunk = bytes.subarray(offset + 8, offset + 8 + length);
    if (type === 0x4e4f534a) json = JSON.parse(chunk.toString('utf8'));
    else if (type === 0x004e4942) bin = new Uint8Array(chunk);
    offset += 8 + length;
  }
  const buffers = (json.buffers || []).map((b, i) => (i === 0 && b.uri === undefined ? bin : null));
  return { json, buffers };
}

/** The accessor's elements as a tightly packed typed array (a copy). */
export function readAccessor(file, index) {
  const accessor = file.json.accessors[index];
  const Type = COMPONENTS[accessor.componentType];
  const size = SIZES[accessor.type];
  const out = new Type(accessor.count * size);
  if (accessor.bufferView === undefined) return out;
  const view = file.json.bufferViews[accessor.bufferView];
  const buffer = file.buffers[view.buffer];
  if (!buffer) throw new Error(`accessor ${index}: buffer ${view.buffer} has no data`);
  const element = Type.BYTES_PER_ELEMENT * size;
  const stride = view.byteStride || element;
  const start = buffer.byteOffset + (view.byteOffset || 0) + (accessor.byteOffset || 0);
  for (let i = 0; i < accessor.count; ++i) {
    const source = new Type(buffer.buffer.slice(start + i * stride, start + i * stride + element));
    out.set(source, i * size);
  }
  return out;
}

export function writeGlb(path, json, bin) {
  const text = Buffer.from(JSON.stringify(json));
  const jsonLength = (text.length + 3) & ~3, binLength = (bin.length + 3) & ~3;
  const out = Buffer.alloc(12 + 8 + jsonLength + 8 + binLength);
  out.writeUInt32LE(0x46546c67, 0); out.writeUInt32LE(2, 4); out.writeUInt32LE(out.length, 8);
  out.writeUInt32LE(jsonLength, 12); out.writeUInt32LE(0x4e4f534a, 16);
  out.fill(0x20, 20, 20 + jsonLength); text.copy(out, 20);
  const binStart = 20 + jsonLength;
  out.writeUInt32LE(binLength, binStart); out.writeUInt32LE(0x004e4942, binStart + 4);
  Buffer.from(bin.buffer, bin.byteOffset, bin.length).copy(out, binStart + 8);
  writeFileSync(path, out);
}
