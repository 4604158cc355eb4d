// cases.mjs - the compressed files every web test reads: each asset in fallback and compact
// mode, and Fox in every method and width (narrow Number path and 64-bit BigInt path), made
// with the skinpack CLI; plus the ground truth `skinpack decompress` writes for each.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, statSync } from 'node:fs';
import { basename, join } from 'node:path';
import { readGltf, writeGlb } from './gltf_file.mjs';
import { SKINPACK_EXTENSION } from '../../web/src/decode.js';

export const CLI = process.env.SKINPACK_CLI;
export const WORK = process.env.SKINPACK_WEB_WORK || '/tmp/skinpack_web';
// Colon-separated .glb paths; Fox first.
export const ASSETS = (process.env.SKINPACK_WEB_ASSETS || '').split(':').filter(Boolean);

export const FOX_VARIANTS = {
  fixed24: ['--method', 'fixed', '--weight-bits', '24'],
  cube21: ['--method', 'cube', '--weight-bits', '21'],
  pot20: ['--method', 'pot', '--weight-bits', '20'],
  any22: ['--method', 'any', '--weight-bits', '22'],
  oss48: ['--method', 'oss', '--vertex-bits', '48'],
  oss64: ['--method', 'oss', '--vertex-bits', '64'],
  any64: ['--method', 'any', '--vertex-bits', '64'],
  fixed64: ['--method', 'fixed', '--vertex-bits', '64'],
  cube64: ['--method', 'cube', '--vertex-bits', '64'],
  pot40: ['--method', 'pot', '--vertex-bits', '40'],
  k1: ['--max-influences', '1'],
  k2: ['--max-influences', '2', '--vertex-bits', '24'],
  k3: ['--max-influences', '3', '--vertex-bits', '32'],
  k3w: ['--max-influences', '3', '--vertex-bits', '62'],
  meshlets: ['--meshlets'], // meshlet data is ignored
};

function run(args) {
  return execFileSync(CLI, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}

// A work file is remade when it is older than the CLI or its source.
function stale(file, ...inputs) {
  if (!existsSync(file)) return true;
  const time = statSync(file).mtimeMs;
  return inputs.some((input) => statSync(input).mtimeMs > time);
}

/** Compresses and decompresses (again when stale); returns {name, source, packed, decoded}. */
export function makeCase(source, tag, args) {
  if (!CLI) throw new Error('SKINPACK_CLI is not set (the ctest registration sets it)');
  mkdirSync(WORK, { recursive: true });
  const name = `${basename(source, '.glb')}_${tag}`;
  const packed = join(WORK, `${name}.glb`), decoded = join(WORK, `${name}_decoded.glb`);
  if (stale(packed, CLI, source)) run(['compress', source, '-o', packed, ...args]);
  if (stale(decoded, CLI, packed)) run(['decompress', packed, '-o', decoded]);
  return { name, source, packed, decoded };
}

/** Every asset fallback + compact, and the Fox variants (fallback). */
export function allCases() {
  const cases = [];
  for (const asset of ASSETS) {
    cases.push(makeCase(asset, 'fallback', ['--fallback']));
    cases.push(makeCase(asset, 'compact', ['--compact']));
  }
  const fox = ASSETS.find((a) => basename(a) === 'Fox.glb');
  if (fox) for (const [tag, args] of Object.entries(FOX_VARIANTS)) cases.push(makeCase(fox, tag, args));
  return cases;
}

/** Issue 10's compact layout: JOINTS_0/WEIGHTS_0 point at bufferViews of a buffer without data
 *  that is marked as our fallback (as EXT_meshopt_compression does). */
export function fallbackBufferLayout(compact, out) {
  const { json, buffers } = readGltf(compact);
  const fallback = json.buffers.length;
  let length = 0;
  const views = new Map();
  for (const mesh of json.meshes) for (const primitive of mesh.primitives) {
    if (!primitive.extensions || !primitive.extensions[SKINPACK_EXTENSION]) continue;
    for (const name of ['JOINTS_0', 'WEIGHTS_0']) {
      const index = primitive.attributes[name];
      if (index === undefined || views.has(index)) continue;
      const accessor = json.accessors[index];
      const bytes = accessor.count * 4 * (accessor.componentType === 5126 ? 4 : accessor.componentType === 5123 ? 2 : 1);
      views.set(index, json.bufferViews.length);
      json.bufferViews.push({ buffer: fallback, byteOffset: length, byteLength: bytes });
      accessor.bufferView = views.get(index);
      length += bytes;
    }
  }
  json.buffers.push({ byteLength: length, extensions: { [SKINPACK_EXTENSION]: { fallback: true } } });
  writeGlb(out, json, buffers[0]);
}
