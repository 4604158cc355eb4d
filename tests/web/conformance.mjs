// conformance.mjs - the spec's conformance vectors (docs/extension/conformance/weights.jsonl)
// with the codecs the library (WebAssembly, through decode.js) builds from their parameters,
// shared by the WebAssembly test and the WebGL2 read-back.
import { existsSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { codecFromExtension } from '../../web/src/decode.js';

export const CONFORMANCE = fileURLToPath(new URL('../../docs/extension/conformance/', import.meta.url));
export const VECTORS = `${CONFORMANCE}weights.jsonl`;

// The vector file writes every integer as a string; the extension JSON writes those up to 2^53
// as numbers (spec 1.0, "Large integers").
function jsonInteger(text) {
  const value = BigInt(text);
  return value <= 2n ** 53n ? Number(value) : text;
}

/** Every vector with its extension parameters, its codec and its code (a BigInt). */
export function readVectors() {
  if (!existsSync(VECTORS)) return null;
  return readFileSync(VECTORS, 'utf8').split('\n').filter(Boolean).map((line) => {
    const vector = JSON.parse(line);
    const ext = { vertices: 0, tupleTable: 0, influences: vector.influences, jointCount: 1, method: vector.method,
      n: jsonInteger(vector.n), weightBits: vector.weightBits, tupleBits: 0 };
    if (vector.method === 'any' && vector.influences > 1) ext.axisSamples = vector.axisSamples.map(jsonInteger);
    const codec = codecFromExtension(ext);
    return { vector, ext, codec, code: BigInt(vector.code) };
  });
}

export function float32Hex(value) {
  return new Uint32Array(new Float32Array([value]).buffer)[0].toString(16).padStart(8, '0');
}
