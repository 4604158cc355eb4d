// gltf_plain.mjs - decodes a file's Draco or meshopt geometry with glTF-Transform and writes it
// without those extensions (plain accessors), for measuring what a compressed file holds.
//   node tools/gltf_plain.mjs IN.glb OUT.glb
import { NodeIO } from '@gltf-transform/core';
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import draco3d from 'draco3dgltf';
import { MeshoptDecoder } from 'meshoptimizer';

const [input, output] = process.argv.slice(2);
if (!input || !output) {
  console.error('usage: node tools/gltf_plain.mjs IN.glb OUT.glb');
  process.exit(2);
}
await MeshoptDecoder.ready;
const io = new NodeIO().registerExtensions(ALL_EXTENSIONS).registerDependencies({
  'draco3d.decoder': await draco3d.createDecoderModule(),
  'meshopt.decoder': MeshoptDecoder,
});
const document = await io.read(input);
for (const extension of document.getRoot().listExtensionsUsed()) {
  if (['KHR_draco_mesh_compression', 'EXT_meshopt_compression', 'KHR_meshopt_compression'].includes(extension.extensionName))
    extension.dispose();
}
await io.write(output, document);
