// constants.test.mjs - the numbers the web runtime copies from the C headers (it cannot include
// them) are the headers' numbers: a limit or layout changed in skinpack.h or the GPU layout
// header without the JS fails here instead of decoding differently.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { MAX_INFLUENCES, MAX_JOINTS, MAX_WEIGHT_BITS, METHODS } from '../../web/src/decode.js';
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

test('limits are skinpack.h\'s', () => {
  assert.equal(MAX_INFLUENCES, library.SP_MAX_INFLUENCES);
  assert.equal(MAX_JOINTS, library.SP_MAX_JOINTS);
  assert.equal(MAX_WEIGHT_BITS, library.SP_MAX_WEIGHT_BITS);
  assert.equal(FALLBACK_VIEW_OFFSET, library.SP_FALLBACK_VIEW_OFFSET);
});

test('method names are in sp_method order', () => {
  const order = [...header('native/include/skinpack.h').matchAll(/^\s*SP_METHOD_([A-Z]+)\s*=\s*(\d+)/gm)]
    .sort((a, b) => Number(a[2]) - Number(b[2])).map((m) => m[1].toLowerCase());
  assert.deepEqual(METHODS, order);
});

test('the 32-bit GPU profile limits are the GPU layout header\'s', () => {
  assert.equal(OSS_NARROW_MAX_CODE_K4, gpu.SP_OSS_NARROW_MAX_CODE_K4);
  assert.equal(OSS_NARROW_MAX_CODE_K3, gpu.SP_OSS_NARROW_MAX_CODE_K3);
});
