// stats.js - per-mesh numbers the viewer shows: bits a vertex before/after, the weight error of
// the decoded skin against the fallback attributes, and the GPU bytes of the skin.

/**
 * Per-vertex L-inf weight error between the decoded influences (4 a vertex) and the original
 * JOINTS_0/WEIGHTS_0 (three.js BufferAttributes; normalised integer weights are read as
 * floats), matched by joint: a joint missing on one side counts with weight 0.
 * @returns {{perVertex: Float32Array, max: number}}
 */
export function weightError(decoded, skinIndex, skinWeight) {
  const count = decoded.weights.length / 4;
  const perVertex = new Float32Array(count);
  let max = 0;
  const ids = new Int32Array(8), ours = new Float64Array(8), theirs = new Float64Array(8);
  for (let v = 0; v < count; ++v) {
    let used = 0, sum = 0;
    const slot = (joint) => {
      for (let i = 0; i < used; ++i) if (ids[i] === joint) return i;
      ids[used] = joint; ours[used] = 0; theirs[used] = 0;
      return used++;
    };
    for (let s = 0; s < 4; ++s) sum += skinWeight.getComponent(v, s);
    const scale = sum > 0 ? 1 / sum : 0; // the original's weights, normalised as the compressor does
    for (let s = 0; s < 4; ++s) {
      const w = skinWeight.getComponent(v, s);
      if (w > 0) theirs[slot(skinIndex.getComponent(v, s))] += w * scale;
      const d = decoded.weights[v * 4 + s];
      if (d > 0) ours[slot(decoded.joints[v * 4 + s])] += d;
    }
    let error = 0;
    for (let i = 0; i < used; ++i) error = Math.max(error, Math.abs(ours[i] - theirs[i]));
    perVertex[v] = error;
    if (error > max) max = error;
  }
  return { perVertex, max };
}

/** Bytes of a glTF accessor's elements: count x components x component size. */
export function accessorBytes(accessor) {
  const components = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[accessor.type] || 0;
  const size = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 }[accessor.componentType] || 0;
  return accessor.count * components * size;
}
