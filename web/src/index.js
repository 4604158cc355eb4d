// skinpack-web: SKINPACK_packed_skin for the web. The three.js plugin (needs the `three` peer
// dependency), the extension's JSON side and libskinpack's validation and decoders as
// WebAssembly; the glTF-Transform extension is `skinpack-web/gltf-transform`.
export * from './decode.js';
export { codecFromParams, decode, LIBRARY_VERSION, paramsEqual, validate } from './wasm.js';
export * from './stats.js';
export { SkinpackGLTFPlugin, SkinpackSkinnedMesh, skinpackData, skinpackMaterial } from './SkinpackGLTFPlugin.js';
