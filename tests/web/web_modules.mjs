// web_modules.mjs - the npm packages of web/ for the tests (tests/ has no node_modules of its own;
// importing by file keeps one instance of @gltf-transform/core for the extension and the tests).
const base = new URL('../../web/node_modules/', import.meta.url);
export const core = await import(new URL('@gltf-transform/core/dist/index.js', base));
export const functions = await import(new URL('@gltf-transform/functions/dist/index.js', base));
export const { MeshoptEncoder } = await import(new URL('meshoptimizer/index.js', base));
