// skinpack-web: SKINPACK_packed_skin for the web. The three.js plugin (needs the `three` peer
// dependency) and the plain-JS decoder; the glTF-Transform extension is `skinpack-web/gltf-transform`.
export * from './decode.js';
export * from './stats.js';
export { SkinpackGLTFPlugin, SkinpackSkinnedMesh, skinpackData, skinpackMaterial } from './SkinpackGLTFPlugin.js';
