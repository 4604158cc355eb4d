// gltf-transform CLI configuration: `gltf-transform <command> in.glb out.glb --config web/gltf-transform/config.mjs`
// keeps SKINPACK_packed_skin (read, preserved through the command, written back) next to the
// extensions the CLI knows.
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import { SkinpackPackedSkin } from './SkinpackPackedSkin.js';

export default { extensions: [...ALL_EXTENSIONS, SkinpackPackedSkin] };
