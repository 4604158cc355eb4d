// constants.test.mjs - the numbers the web runtime still copies from the C headers (it cannot
// include them) are the headers' numbers: a limit or layout changed in skinpack.h or the GPU
// layout header without the JS fails here instead of decoding differently. The format rules
// themselves are the library's (WebAssembly): the JS modules must not export copies of them.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import * as decode from '../../web/src/decode.js';
import * as wasm from '../../web/src/wasm.js';
import { OSS_NARROW_MAX_CODE_K3, OSS_NARROW_MAX_CODE_K4 } from '../../web/src/gpu.js';
import { FALLBACK_VIEW_OFFSET } from '../../web/gltf-transform/SkinpackPackedSkin.js';

function header(relative) {
  return readFileSync(fileURLToPath(new URL(`../../${relative}`, import.meta.url)), 'utf8');
}

// `#define SP_NAME 123` (an optional u suffix) of a header, by name.
function defines(text) {
  const out = {};
  for (const [, name, value] of text.matchAll(/^\s*#define\s+(SP_[A-Z0-9_]+)\s+(\d+)u?\b/gm)) out[name] = Number(value);
  return out;
}

const library = defines(header('native/include/skinpack.h'));
const gpu = defines(header('shaders/skinpack_gpu_layout.h'));

test('the fallback view offset and the module\'s version are skinpack.h\'s', () => {
  assert.equal(FALLBACK_VIEW_OFFSET, library.SP_FALLBACK_VIEW_OFFSET);
  assert.equal(wasm.LIBRARY_VERSION, library.SP_VERSION, 'web/wasm/skinpack.wasm is stale: rebuild it');
});

// What decode.js may export: the JSON/container side and thin calls into the library. A JS
// decoder, limit or closed form exported again (decodeWeightCode, ossRowBase, MAX_JOINTS, …)
// fails here; so does a jointBytes or METHODS that is not the library's own.
const CONTAINER_SIDE = ['METHODS', 'SKINPACK_EXTENSION', 'SkinpackDecodeError', 'codecFromExtension', 'compactLayout',
  'decodeSkin', 'extensionParams', 'isFallbackBuffer', 'jointBytes', 'parseLargeInteger'];
test('decode.js exports only the container side; the rules are the library\'s', () => {
  assert.deepEqual(Object.keys(decode).sort(), CONTAINER_SIDE.sort());
  assert.equal(decode.jointBytes, wasm.jointBytes);
  assert.equal(decode.METHODS, wasm.METHODS);
  assert.equal(decode.SkinpackDecodeError, wasm.SkinpackDecodeError);
  // The header's limits, as the library applies them (not as JS constants).
  assert.equal(decode.jointBytes(library.SP_MAX_JOINTS), 2);
  assert.equal(decode.jointBytes(library.SP_MAX_JOINTS + 1), 0);
  assert.equal(decode.jointBytes(256), 1);
});

test('method names are in sp_method order', () => {
  const order = [...header('native/include/skinpack.h').matchAll(/^\s*SP_METHOD_([A-Z]+)\s*=\s*(\d+)/gm)]
    .sort((a, b) => Number(a[2]) - Number(b[2])).map((m) => m[1].toLowerCase());
  assert.deepEqual(decode.METHODS, order);
});

test('the 32-bit GPU profile limits are the GPU layout header\'s', () => {
  assert.equal(OSS_NARROW_MAX_CODE_K4, gpu.SP_OSS_NARROW_MAX_CODE_K4);
  assert.equal(OSS_NARROW_MAX_CODE_K3, gpu.SP_OSS_NARROW_MAX_CODE_K3);
});
