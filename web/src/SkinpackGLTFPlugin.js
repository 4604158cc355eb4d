// SkinpackGLTFPlugin.js - SKINPACK_packed_skin for three.js's GLTFLoader.
//
//   loader.register((parser) => new SkinpackGLTFPlugin(parser, { decode: 'gpu' }));
//
// decode: 'gpu' (default) keeps the packed words as a uint vertex attribute and the tuple table
// as an RGBA16UI texture, and patches the materials' skinning chunks to decode per vertex;
// codecs outside the 32-bit GPU profile fall back to the CPU path (userData.skinpack says why).
// 'cpu' decodes into the standard skinIndex/skinWeight attributes. Both modes read fallback and
// compact files; errors reject the load with a message naming the mesh and primitive. The packed
// arrays are read through the parser (getDependency), so files of `skinpack compress --meshopt`
// load once the loader has loader.setMeshoptDecoder(MeshoptDecoder) (three/addons/libs/
// meshopt_decoder.module.js); without it three.js rejects them.

import {
  BufferAttribute, DataTexture, MeshDepthMaterial, MeshDistanceMaterial, NearestFilter, RGBADepthPacking,
  RGBAIntegerFormat, SkinnedMesh, UnsignedShortType,
} from 'three';
import { compactLayout, extensionParams, isFallbackBuffer, SKINPACK_EXTENSION } from './decode.js';
import { decode, paramsEqual } from './wasm.js';
import { codecProgramKey, gpuProfileRefusal, gpuSkinUniforms, patchSkinningShader, tupleTexels } from './gpu.js';

const COMPONENT_UNSIGNED_BYTE = 5121, COMPONENT_UNSIGNED_SHORT = 5123, COMPONENT_UNSIGNED_INT = 5125;
const TABLE_TYPES = ['SCALAR', 'VEC2', 'VEC3', 'VEC4'];
const components = (type) => TABLE_TYPES.indexOf(type) + 1;

// Per geometry: the codec, the packed arrays, the decoded skin and (fallback files) the original
// attributes. Kept out of userData, which three.js clones through JSON.
const DATA = new WeakMap();

/** What the plugin knows about a mesh (or geometry) it decoded, or undefined. */
export function skinpackData(meshOrGeometry) {
  return DATA.get(meshOrGeometry.isBufferGeometry ? meshOrGeometry : meshOrGeometry.geometry);
}

function primitiveName(meshIndex, meshDef, p) {
  return `mesh ${meshIndex}${meshDef.name ? ` "${meshDef.name}"` : ''} primitive ${p}`;
}

export class SkinpackGLTFPlugin {
  /**
   * @param {object} parser  GLTFParser
   * @param {{decode?: 'gpu'|'cpu'}} [options]
   */
  constructor(parser, options = {}) {
    this.name = SKINPACK_EXTENSION;
    this.parser = parser;
    this.decode = options.decode || 'gpu';
    if (this.decode !== 'gpu' && this.decode !== 'cpu') throw new Error(`SkinpackGLTFPlugin: decode must be 'gpu' or 'cpu', not ${this.decode}`);
  }

  // Primitives sharing the packed words must declare the same properties (spec 1.0, Accessors;
  // the library's sp_packed_params_equal says which are the same).
  beforeRoot() {
    const seen = new Map();
    const meshes = this.parser.json.meshes || [];
    for (let m = 0; m < meshes.length; ++m) {
      for (let p = 0; p < meshes[m].primitives.length; ++p) {
        const ext = meshes[m].primitives[p].extensions && meshes[m].primitives[p].extensions[SKINPACK_EXTENSION];
        if (!ext) continue;
        const where = primitiveName(m, meshes[m], p);
        let params;
        try {
          params = extensionParams(ext);
        } catch (error) {
          return Promise.reject(new Error(`SkinpackGLTFPlugin: ${where}: ${error.message}`));
        }
        const first = seen.get(ext.vertices);
        if (first && !paramsEqual(first.params, params))
          return Promise.reject(new Error(`SkinpackGLTFPlugin: ${where}: shares "vertices" accessor ${ext.vertices} with ${first.where} but declares different properties`));
        if (first && first.tupleTable !== ext.tupleTable)
          return Promise.reject(new Error(`SkinpackGLTFPlugin: ${where}: shares "vertices" accessor ${ext.vertices} with ${first.where} but declares another "tupleTable"`));
        if (!first) seen.set(ext.vertices, { params, where, tupleTable: ext.tupleTable });
      }
    }
    return null;
  }

  // Buffers marked as our fallback (compact mode, EXT_meshopt_compression style) have no data:
  // their bufferViews (only JOINTS_0/WEIGHTS_0 point at them) load as zeros and are replaced.
  loadBufferView(index) {
    const json = this.parser.json;
    const view = json.bufferViews[index];
    if (!isFallbackBuffer(json.buffers[view.buffer])) return null;
    return Promise.resolve(new ArrayBuffer(view.byteLength || 0));
  }

  loadMesh(meshIndex) {
    const meshDef = this.parser.json.meshes[meshIndex];
    if (!meshDef.primitives.some((p) => p.extensions && p.extensions[SKINPACK_EXTENSION])) return null;
    return this.parser.loadMesh(meshIndex).then((object) => {
      const meshes = object.isGroup ? object.children : [object];
      return Promise.all(meshDef.primitives.map((primitive, p) => {
        const ext = primitive.extensions && primitive.extensions[SKINPACK_EXTENSION];
        if (!ext) return null;
        const where = primitiveName(meshIndex, meshDef, p);
        return this._decodePrimitive(meshIndex, primitive, ext, where)
          .then((packed) => this._attach(meshes[p], packed, where))
          .catch((error) => { throw new Error(`SkinpackGLTFPlugin: ${where}: ${error.message}`); });
      })).then(() => object);
    });
  }

  // Reads the extension's accessors (the glTF side: types, ranges in their buffers) and hands
  // them to the library, which checks every format rule and decodes every vertex. Both paths
  // need that: the GPU path's shader assumes valid data, and its bounding volumes and raycasts
  // skin on the CPU from the decoded values.
  async _decodePrimitive(meshIndex, primitive, ext, where) {
    const json = this.parser.json;
    const params = extensionParams(ext);
    const wordsDef = json.accessors[ext.vertices], tableDef = json.accessors[ext.tupleTable];
    if (!wordsDef) throw new Error(`"vertices" = ${ext.vertices} is not an accessor`);
    if (!tableDef) throw new Error(`"tupleTable" = ${ext.tupleTable} is not an accessor`);
    if (wordsDef.componentType !== COMPONENT_UNSIGNED_INT || !['SCALAR', 'VEC2'].includes(wordsDef.type))
      throw new Error(`"vertices" accessor ${ext.vertices} must be UNSIGNED_INT SCALAR or VEC2`);
    if (![COMPONENT_UNSIGNED_BYTE, COMPONENT_UNSIGNED_SHORT].includes(tableDef.componentType) || !TABLE_TYPES.includes(tableDef.type))
      throw new Error(`"tupleTable" accessor ${ext.tupleTable} must be UNSIGNED_BYTE or UNSIGNED_SHORT, SCALAR to VEC4`);
    for (const [field, accessor] of [['vertices', wordsDef], ['tupleTable', tableDef]]) this._checkAccessor(field, ext[field], accessor);
    const position = json.accessors[primitive.attributes.POSITION];
    const [wordsAttribute, tableAttribute] = await Promise.all([
      this.parser.getDependency('accessor', ext.vertices), this.parser.getDependency('accessor', ext.tupleTable)]);
    const words = wordsAttribute.array, lut = tableAttribute.array;
    const { codec, ...decoded } = decode({
      params, words, wordsPerVertex: components(wordsDef.type), primitiveVertexCount: position ? position.count : undefined,
      lut, lutComponents: components(tableDef.type), skinJointCount: this._skinJointCount(meshIndex),
    });
    return { codec, words, lut, decoded, compact: compactLayout(json, primitive) !== null };
  }

  // Tightly packed, not normalized, not sparse, inside its bufferView (spec 1.0, Accessors).
  _checkAccessor(field, index, accessor) {
    const json = this.parser.json;
    const name = `"${field}" accessor ${index}`;
    if (accessor.bufferView === undefined) throw new Error(`${name} has no bufferView`);
    if (accessor.sparse || accessor.normalized) throw new Error(`${name} must be neither sparse nor normalized`);
    const view = json.bufferViews[accessor.bufferView];
    if (!view) throw new Error(`${name}: bufferView ${accessor.bufferView} does not exist`);
    const componentBytes = { [COMPONENT_UNSIGNED_BYTE]: 1, [COMPONENT_UNSIGNED_SHORT]: 2, [COMPONENT_UNSIGNED_INT]: 4 }[accessor.componentType];
    const size = componentBytes * components(accessor.type); // types were checked above
    if (view.byteStride && view.byteStride !== size) throw new Error(`${name} must be tightly packed (byteStride ${view.byteStride})`);
    const end = (accessor.byteOffset || 0) + accessor.count * size;
    if (end > view.byteLength) throw new Error(`${name} ends at byte ${end}, past its bufferView's ${view.byteLength}`);
    const buffer = json.buffers[view.buffer];
    if (!buffer || (view.byteOffset || 0) + view.byteLength > buffer.byteLength)
      throw new Error(`${name}: bufferView ${accessor.bufferView} lies outside its buffer`);
  }

  // Joints of the smallest skin of the nodes that use the mesh (0: none), which the declared
  // jointCount must not exceed.
  _skinJointCount(meshIndex) {
    const json = this.parser.json;
    let smallest = 0;
    for (const node of json.nodes || []) {
      if (node.mesh !== meshIndex || node.skin === undefined) continue;
      const joints = json.skins[node.skin].joints.length;
      if (!smallest || joints < smallest) smallest = joints;
    }
    return smallest;
  }

  _attach(mesh, packed, where) {
    if (!mesh || !mesh.isSkinnedMesh) {
      // Not bound to a skin: nothing deforms it, the packed data is ignored (as three ignores JOINTS_0).
      return;
    }
    const { codec, decoded } = packed;
    const refusal = this.decode === 'gpu' ? gpuProfileRefusal(codec) : 'CPU decode requested';
    const geometry = mesh.geometry;
    const info = {
      decode: refusal ? 'cpu' : 'gpu', reason: refusal, compact: packed.compact, method: codec.method,
      influences: codec.influences, weightBits: codec.weightBits, tupleBits: codec.tupleBits,
      vertexCount: decoded.vertexCount, tupleCount: packed.lut.length / codec.influences, gpuSkinBytes: 0,
    };
    mesh.userData.skinpack = info;
    DATA.set(geometry, { ...packed, info, original: packed.compact ? null : {
      skinIndex: geometry.getAttribute('skinIndex'), skinWeight: geometry.getAttribute('skinWeight') } });
    if (refusal) {
      if (this.decode === 'gpu') console.warn(`SkinpackGLTFPlugin: ${where}: CPU decode: ${refusal}`);
      geometry.setAttribute('skinIndex', new BufferAttribute(decoded.joints, 4)); // u8 or u16, as glTF stores them
      geometry.setAttribute('skinWeight', new BufferAttribute(decoded.weights, 4));
      info.gpuSkinBytes = decoded.joints.byteLength + decoded.weights.byteLength;
      return;
    }
    attachGpuSkin(mesh, packed);
  }
}

/**
 * The class of GPU-decoded meshes. Bounding volumes and raycasts skin on the CPU from the
 * decoded values kept in JS memory (attached for the call only, never uploaded); copies keep
 * the patched shadow materials.
 */
export class SkinpackSkinnedMesh extends SkinnedMesh {
  applyBoneTransform(index, target) {
    const data = DATA.get(this.geometry);
    if (!data || !data.cpuSkin) return super.applyBoneTransform(index, target);
    const attributes = this.geometry.attributes;
    attributes.skinIndex = data.cpuSkin.skinIndex;
    attributes.skinWeight = data.cpuSkin.skinWeight;
    try {
      return super.applyBoneTransform(index, target);
    } finally {
      delete attributes.skinIndex;
      delete attributes.skinWeight;
    }
  }

  copy(source, recursive) {
    super.copy(source, recursive);
    this.customDepthMaterial = source.customDepthMaterial;
    this.customDistanceMaterial = source.customDistanceMaterial;
    return this;
  }
}

/**
 * A copy of material that skins from the packed words of mesh (which the plugin set up for GPU
 * decode), for materials an application assigns after loading. Any material whose vertex
 * shader includes three's skinning chunks works.
 */
export function skinpackMaterial(mesh, material) {
  const data = skinpackData(mesh);
  if (!data || !data.uniforms) throw new Error('skinpackMaterial: the mesh does not use GPU decode');
  const patched = material.clone();
  patched.onBeforeCompile = (shader) => patchSkinningShader(shader, data.uniforms, data.codec);
  patched.customProgramCacheKey = () => codecProgramKey(data.codec);
  return patched;
}

/**
 * Switches a skinned mesh loaded by the plugin to GPU decode: the words as a uint attribute,
 * the tuple table as a texture, the material (and shadow materials) patched. The decoded
 * joints/weights stay in JS memory only, for bounding spheres and raycasts.
 */
export function attachGpuSkin(mesh, packed) {
  const { codec, words, lut, decoded } = packed;
  const geometry = mesh.geometry;
  const { texels, width, height } = tupleTexels(lut, codec.influences);
  const texture = new DataTexture(texels, width, height, RGBAIntegerFormat, UnsignedShortType);
  texture.internalFormat = 'RGBA16UI';
  texture.magFilter = texture.minFilter = NearestFilter;
  texture.generateMipmaps = false;
  texture.needsUpdate = true;
  const uniforms = gpuSkinUniforms(codec, texture); // the other codec parameters are shader constants
  geometry.deleteAttribute('skinIndex');
  geometry.deleteAttribute('skinWeight');
  geometry.setAttribute('skinpackWord', new BufferAttribute(words, 1));
  DATA.get(geometry).uniforms = uniforms;
  const patch = (material) => skinpackMaterial(mesh, material);
  mesh.material = Array.isArray(mesh.material) ? mesh.material.map(patch) : patch(mesh.material);
  mesh.customDepthMaterial = patch(new MeshDepthMaterial({ depthPacking: RGBADepthPacking }));
  mesh.customDistanceMaterial = patch(new MeshDistanceMaterial());
  DATA.get(geometry).cpuSkin = { skinIndex: new BufferAttribute(decoded.joints, 4), skinWeight: new BufferAttribute(decoded.weights, 4) };
  Object.setPrototypeOf(mesh, SkinpackSkinnedMesh.prototype); // clones (SkeletonUtils.clone, .clone()) stay GPU-decoded too
  mesh.userData.skinpack.gpuSkinBytes = words.byteLength + texels.byteLength;
}
