// SkinpackPackedSkin.js - SKINPACK_packed_skin for glTF-Transform (an Extension subclass).
//
//   const io = new NodeIO().registerExtensions([SkinpackPackedSkin]);
//
// In memory the packed words are a custom vertex attribute `_SKINPACK_WORDS` of the primitive,
// so every operation that reorders, welds or splits vertices (weld, reorder, dedup, join, …)
// carries them along with POSITION; the tuple table and the codec parameters live in a
// PackedSkin property on the primitive. On write the attribute becomes the extension's
// `vertices` accessor again (own bufferView, no target), compact primitives get their
// JOINTS_0/WEIGHTS_0 placeholders without data back, and every primitive is decoded once: a
// result that no longer decodes (or whose word count left the vertex count) makes the write
// throw, naming the mesh and primitive, instead of writing a silently wrong skin.
// Meshlets index vertices and triangles; operations invalidate them, so they are dropped on read.
// Compact files are written in the fallback-buffer layout the spec gives (JOINTS_0/WEIGHTS_0
// accessors whose bufferViews lie in a buffer without data, marked as the extension's fallback),
// so a loader without the extension refuses them; the reader gives such views zero bytes.

import { Extension, ExtensionProperty, PropertyType } from '@gltf-transform/core';
import { compactLayout, extensionParams, isFallbackBuffer, jointBytes, SKINPACK_EXTENSION } from '../src/decode.js';
import { validate } from '../src/wasm.js';

export const WORDS_ATTRIBUTE = '_SKINPACK_WORDS';
const PARAMETERS = ['influences', 'jointCount', 'method', 'n', 'axisSamples', 'weightBits', 'tupleBits', 'maxError'];
const UNSIGNED_BYTE = 5121, UNSIGNED_SHORT = 5123, FLOAT = 5126;
// The fallback buffer's views start here: three.js fetches a buffer without uri as the page
// itself, and an offset past any page makes that fetch fail too (docs/extension/README.md).
export const FALLBACK_VIEW_OFFSET = 1 << 24;

/** The extension on one primitive: the tuple table accessor and the codec parameters. */
export class PackedSkin extends ExtensionProperty {
  static EXTENSION_NAME = SKINPACK_EXTENSION;

  init() {
    this.extensionName = SKINPACK_EXTENSION;
    this.propertyType = 'PackedSkin';
    this.parentTypes = [PropertyType.PRIMITIVE];
  }

  getDefaults() {
    return Object.assign(super.getDefaults(), { tupleTable: null, parameters: {}, compact: false });
  }

  getTupleTable() { return this.getRef('tupleTable'); }
  setTupleTable(accessor) { return this.setRef('tupleTable', accessor, { usage: 'SKINPACK_TUPLE_TABLE' }); }
  /** influences, jointCount, method, n, axisSamples, weightBits, tupleBits, maxError. */
  getParameters() { return { ...this.get('parameters') }; }
  setParameters(parameters) { return this.set('parameters', { ...parameters }); }
  /** Compact: JOINTS_0/WEIGHTS_0 are written as accessors without data. */
  getCompact() { return this.get('compact'); }
  setCompact(compact) { return this.set('compact', compact); }
}

export class SkinpackPackedSkin extends Extension {
  static EXTENSION_NAME = SKINPACK_EXTENSION;
  extensionName = SKINPACK_EXTENSION;
  prewriteTypes = [PropertyType.ACCESSOR];
  prereadTypes = [PropertyType.BUFFER];

  createPackedSkin() {
    return new PackedSkin(this.document.getGraph());
  }

  // Views of a fallback buffer have no bytes to read: zeros stand in for the placeholders, which
  // read() then removes (the packed words are the primitive's skin).
  preread(context) {
    const json = context.jsonDoc.json;
    (json.bufferViews || []).forEach((viewDef, index) => {
      if (isFallbackBuffer((json.buffers || [])[viewDef.buffer])) context.bufferViews[index] = new Uint8Array(viewDef.byteLength);
    });
    return this;
  }

  read(context) {
    const json = context.jsonDoc.json;
    (json.meshes || []).forEach((meshDef, m) => meshDef.primitives.forEach((primitiveDef, p) => {
      const def = primitiveDef.extensions && primitiveDef.extensions[SKINPACK_EXTENSION];
      if (!def) return;
      const where = `mesh ${m} primitive ${p}`;
      const primitive = context.meshes[m].listPrimitives()[p];
      const words = context.accessors[def.vertices], table = context.accessors[def.tupleTable];
      if (!words || !table) throw new Error(`${SKINPACK_EXTENSION}: ${where}: "vertices" or "tupleTable" is not an accessor`);
      const packed = this.createPackedSkin().setTupleTable(table);
      const parameters = {};
      for (const key of PARAMETERS) if (def[key] !== undefined) parameters[key] = def[key];
      packed.setParameters(parameters);
      if (def.meshlets) this.document.getLogger().warn(`${SKINPACK_EXTENSION}: ${where}: meshlets dropped (operations invalidate them; rebuild with skinpack compress --meshlets)`);
      const compact = compactLayout(json, primitiveDef) !== null;
      packed.setCompact(compact);
      if (compact) for (const name of ['JOINTS_0', 'WEIGHTS_0']) {
        const placeholder = primitive.getAttribute(name);
        primitive.setAttribute(name, null);
        if (placeholder && placeholder.listParents().length <= 1) placeholder.dispose();
      }
      primitive.setAttribute(WORDS_ATTRIBUTE, words);
      primitive.setExtension(SKINPACK_EXTENSION, packed);
    }));
    // A data-less fallback buffer is unused now (GLB holds one buffer): dropped.
    (json.buffers || []).forEach((bufferDef, b) => {
      const buffer = context.buffers[b];
      if (isFallbackBuffer(bufferDef) && buffer && buffer.listParents().every((p) => p.propertyType === PropertyType.ROOT)) buffer.dispose();
    });
    return this;
  }

  // Each packed array on its own bufferView without target (docs/extension/README.md).
  prewrite(context) {
    const usages = new Map();
    for (const packed of this.properties) {
      for (const primitive of packed.listParents().filter((p) => p.propertyType === PropertyType.PRIMITIVE)) {
        const words = primitive.getAttribute(WORDS_ATTRIBUTE);
        for (const accessor of [words, packed.getTupleTable()]) {
          if (!accessor || usages.has(accessor)) continue;
          usages.set(accessor, `SKINPACK_packed_skin:${usages.size}`);
          context.addAccessorToUsageGroup(accessor, usages.get(accessor));
        }
      }
    }
    return this;
  }

  write(context) {
    const json = context.jsonDoc.json;
    const placeholders = { views: [], byteLength: FALLBACK_VIEW_OFFSET };
    this.document.getRoot().listMeshes().forEach((mesh) => {
      const meshIndex = context.meshIndexMap.get(mesh);
      mesh.listPrimitives().forEach((primitive, p) => {
        const packed = primitive.getExtension(SKINPACK_EXTENSION);
        if (!packed) return;
        const where = `${SKINPACK_EXTENSION}: mesh ${meshIndex}${mesh.getName() ? ` "${mesh.getName()}"` : ''} primitive ${p}`;
        const primitiveDef = json.meshes[meshIndex].primitives[p];
        const words = primitive.getAttribute(WORDS_ATTRIBUTE), table = packed.getTupleTable();
        if (!words || !table) throw new Error(`${where}: the packed words or the tuple table are gone`);
        const def = { vertices: context.accessorIndexMap.get(words), tupleTable: context.accessorIndexMap.get(table), ...packed.getParameters() };
        checkDecodes(def, primitive, words, table, where);
        delete primitiveDef.attributes[WORDS_ATTRIBUTE];
        primitiveDef.extensions = primitiveDef.extensions || {};
        primitiveDef.extensions[SKINPACK_EXTENSION] = def;
        if (packed.getCompact()) addPlaceholders(json, primitiveDef, words.getCount(), def.jointCount, placeholders);
      });
    });
    if (placeholders.views.length) addFallbackBuffer(json, placeholders);
    if (placeholders.views.length && !(json.extensionsRequired || []).includes(SKINPACK_EXTENSION))
      (json.extensionsRequired = json.extensionsRequired || []).push(SKINPACK_EXTENSION);
    return this;
  }
}

// The write refuses what would decode wrongly (word count off the vertex count, bad data): the
// library validates the primitive as a reader will find it.
function checkDecodes(def, primitive, words, table, where) {
  const position = primitive.getAttribute('POSITION');
  try {
    validate({ params: extensionParams(def), words: words.getArray(), wordsPerVertex: words.getElementSize(),
      primitiveVertexCount: position ? position.getCount() : undefined, lut: table.getArray(), lutComponents: table.getElementSize() });
  } catch (error) {
    throw new Error(`${where}: ${error.message}`);
  }
}

// Compact mode: JOINTS_0/WEIGHTS_0 accessors on views of the fallback buffer (no data).
function addPlaceholders(json, primitiveDef, count, jointCount, placeholders) {
  json.accessors = json.accessors || [];
  json.bufferViews = json.bufferViews || [];
  const add = (componentType, bytesPerComponent) => {
    const byteLength = count * 4 * bytesPerComponent; // VEC4, a multiple of 4
    const view = json.bufferViews.push({ buffer: -1, byteOffset: placeholders.byteLength, byteLength }) - 1;
    placeholders.views.push(view);
    placeholders.byteLength += byteLength;
    return json.accessors.push({ bufferView: view, componentType, count, type: 'VEC4' }) - 1;
  };
  const jointSize = jointBytes(jointCount);
  primitiveDef.attributes.JOINTS_0 = add(jointSize === 2 ? UNSIGNED_SHORT : UNSIGNED_BYTE, jointSize);
  primitiveDef.attributes.WEIGHTS_0 = add(FLOAT, 4);
}

// The buffer the placeholders' views lie in: byteLength only, marked as the fallback, never buffer 0.
function addFallbackBuffer(json, placeholders) {
  json.buffers = json.buffers || [];
  const buffer = json.buffers.push({ byteLength: placeholders.byteLength, extensions: { [SKINPACK_EXTENSION]: { fallback: true } } }) - 1;
  for (const view of placeholders.views) json.bufferViews[view].buffer = buffer;
}
