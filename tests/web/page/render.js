// render.js - what the browser tests run in Chromium: render a file with plain three.js or with
// SkinpackGLTFPlugin (GPU or CPU decode) at fixed poses and return the pixels; decode the packed
// words in a raw WebGL2 shader into an integer render target and read them back.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { SkinpackGLTFPlugin, skinpackData } from '/src/SkinpackGLTFPlugin.js';
import { codecDivisors, decodeGlsl, tupleTexels } from '/src/gpu.js';
import { codecFromExtension } from '/src/decode.js';

const SIZE = 256;
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(SIZE, SIZE);
renderer.shadowMap.enabled = true;
document.body.appendChild(renderer.domElement);

function load(url, decode) {
  const loader = new GLTFLoader();
  if (decode) loader.register((parser) => new SkinpackGLTFPlugin(parser, { decode }));
  return loader.loadAsync(url);
}

// A pose every file gets on top of its animation, so files without animations still deform,
// and morph target weights, so morphing and skinning are tested together.
function pose(gltf, time) {
  gltf.scene.traverse((o) => {
    if (o.morphTargetInfluences) o.morphTargetInfluences.forEach((_, i, all) => { all[i] = 0.5 + 0.5 * Math.sin(time * 3 + i); });
  });
  const bones = [];
  gltf.scene.traverse((o) => { if (o.isBone) bones.push(o); });
  bones.forEach((bone, i) => {
    bone.rotation.x += 0.25 * Math.sin(1.7 * i + time);
    bone.rotation.z += 0.25 * Math.cos(2.3 * i + time);
  });
}

function stage(gltf) {
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x303040);
  scene.add(gltf.scene);
  gltf.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(gltf.scene); // bind-pose geometry bounds: the same for every variant
  const center = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length();
  const camera = new THREE.PerspectiveCamera(40, 1, size / 100, size * 10);
  camera.position.copy(center).add(new THREE.Vector3(0.6, 0.35, 1).multiplyScalar(size * 1.25));
  camera.lookAt(center);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.5));
  const light = new THREE.DirectionalLight(0xffffff, 2);
  light.position.copy(center).add(new THREE.Vector3(size, size * 2, size));
  light.target.position.copy(center);
  light.castShadow = true;
  light.shadow.mapSize.set(512, 512);
  Object.assign(light.shadow.camera, { left: -size, right: size, top: size, bottom: -size, near: size / 100, far: size * 5 });
  scene.add(light, light.target);
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(size * 3, size * 3), new THREE.MeshStandardMaterial({ color: 0x808080 }));
  ground.rotation.x = -Math.PI / 2;
  ground.position.y = box.min.y;
  ground.receiveShadow = true;
  scene.add(ground);
  gltf.scene.traverse((o) => { if (o.isMesh) { o.castShadow = true; o.frustumCulled = false; } });
  return { scene, camera };
}

function pixels() {
  const gl = renderer.getContext();
  const out = new Uint8Array(SIZE * SIZE * 4);
  gl.readPixels(0, 0, SIZE, SIZE, gl.RGBA, gl.UNSIGNED_BYTE, out);
  return out;
}

function toBase64(bytes) {
  let text = '';
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode.apply(null, bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

/** Renders url at each time; decode: null (plain three.js), 'gpu' or 'cpu'; copy: render a SkeletonUtils clone. */
async function render(url, decode, times, copy = false) {
  const gltf = await load(url, decode);
  if (copy) {
    const { clone } = await import('three/addons/utils/SkeletonUtils.js');
    gltf.scene = clone(gltf.scene);
  }
  const { scene, camera } = stage(gltf);
  const mixer = gltf.animations.length ? new THREE.AnimationMixer(gltf.scene) : null;
  if (mixer) mixer.clipAction(gltf.animations[0]).play();
  const images = [], modes = [];
  let skinnedMorphs = 0;
  gltf.scene.traverse((o) => {
    if (o.userData.skinpack) modes.push(o.userData.skinpack.decode);
    if (o.isSkinnedMesh && o.morphTargetInfluences) skinnedMorphs++;
  });
  const rest = new Map();
  gltf.scene.traverse((o) => { if (o.isBone) rest.set(o, o.quaternion.clone()); });
  for (const time of times) {
    rest.forEach((q, bone) => bone.quaternion.copy(q));
    if (mixer) mixer.setTime(time);
    pose(gltf, time);
    renderer.render(scene, camera);
    images.push(toBase64(pixels()));
  }
  renderer.renderLists.dispose();
  return { images, modes, skinnedMorphs, size: SIZE, info: { ...renderer.info.memory } };
}

/** Plain three.js: the load error, or what its skin attributes hold (distinct weight vectors, largest joint). */
async function plainSkinWeights(url) {
  try {
    const gltf = await load(url, null);
    const weights = new Set();
    let maxJoint = 0;
    gltf.scene.traverse((o) => {
      if (!o.isSkinnedMesh) return;
      const w = o.geometry.getAttribute('skinWeight'), j = o.geometry.getAttribute('skinIndex');
      for (let v = 0; v < w.count; ++v) weights.add([w.getX(v), w.getY(v), w.getZ(v), w.getW(v)].join());
      for (const joint of j.array) maxJoint = Math.max(maxJoint, joint);
    });
    return { weights: [...weights], maxJoint };
  } catch (error) {
    return { error: String(error && error.message ? error.message : error) };
  }
}

async function loadError(url, decode) {
  try {
    await load(url, decode);
    return null;
  } catch (error) {
    return String(error && error.message ? error.message : error);
  }
}

// ---- GPU decode read back through an integer render target -------------------------------------

// The decoder the skinning shaders run, for one codec (its constants) and tuple row width.
const readbackVertex = (codec, rowWidth) => `#version 300 es
precision highp float; precision highp int; precision highp usampler2D;
in highp uint skinpackWord;
uniform highp uint width;
${decodeGlsl(codec, rowWidth)}
flat out highp uvec4 vQ, vJ, vW;
void main() {
  highp uvec4 joints; highp vec4 weights; highp uvec4 q;
  skinpackDecode(skinpackWord, joints, weights, q);
  vQ = q; vJ = joints; vW = floatBitsToUint(weights);
  uint id = uint(gl_VertexID);
  gl_Position = vec4((float(id % width) + 0.5) / float(width) * 2.0 - 1.0, (float(id / width) + 0.5) / float(width) * 2.0 - 1.0, 0.0, 1.0);
  gl_PointSize = 1.0;
}`;
const READBACK_FRAGMENT = `#version 300 es
precision highp float; precision highp int;
flat in highp uvec4 vQ, vJ, vW;
layout(location = 0) out highp uvec4 outQ;
layout(location = 1) out highp uvec4 outJ;
layout(location = 2) out highp uvec4 outW;
void main() { outQ = vQ; outJ = vJ; outW = vW; }`;

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
  return shader;
}

let readback = null; // one WebGL2 context for every read-back, one program per decoder source

function readbackContext() {
  if (readback) return readback;
  const canvas = document.createElement('canvas');
  const gl = canvas.getContext('webgl2');
  readback = { gl, programs: new Map(), fragment: compile(gl, gl.FRAGMENT_SHADER, READBACK_FRAGMENT), table: gl.createTexture(),
               words: gl.createBuffer(), framebuffer: gl.createFramebuffer(), targets: [0, 1, 2].map(() => gl.createTexture()) };
  return readback;
}

function readbackProgram(codec, rowWidth) {
  const { gl, programs, fragment } = readbackContext();
  const source = readbackVertex(codec, rowWidth);
  if (!programs.has(source)) {
    const program = gl.createProgram();
    gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, source));
    gl.attachShader(program, fragment);
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
    programs.set(source, program);
  }
  return programs.get(source);
}

/** Decodes words (one a vertex) with tuple table lut in the shader; returns q, joints, weight bits. */
function gpuDecode(codec, words, lut, rowWidth) {
  const { gl, table, words: buffer, framebuffer, targets } = readbackContext();
  const program = readbackProgram(codec, rowWidth);
  const vertexCount = words.length;
  const width = Math.max(1, Math.ceil(Math.sqrt(vertexCount)));
  gl.useProgram(program);
  const { texels, width: lutWidth, height: lutHeight } = tupleTexels(lut, codec.influences, rowWidth);
  gl.activeTexture(gl.TEXTURE0);
  gl.bindTexture(gl.TEXTURE_2D, table);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA16UI, lutWidth, lutHeight, 0, gl.RGBA_INTEGER, gl.UNSIGNED_SHORT, texels);
  gl.uniform1i(gl.getUniformLocation(program, 'skinpackTuples'), 0);
  gl.uniform1ui(gl.getUniformLocation(program, 'width'), width);
  gl.uniform4fv(gl.getUniformLocation(program, 'skinpackDivisors'), codecDivisors(codec));
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  gl.bufferData(gl.ARRAY_BUFFER, words, gl.STATIC_DRAW);
  const location = gl.getAttribLocation(program, 'skinpackWord');
  gl.enableVertexAttribArray(location);
  gl.vertexAttribIPointer(location, 1, gl.UNSIGNED_INT, 0, 0);
  gl.bindFramebuffer(gl.FRAMEBUFFER, framebuffer);
  gl.activeTexture(gl.TEXTURE1); // keep the tuple table bound on unit 0
  targets.forEach((t, i) => {
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32UI, width, width, 0, gl.RGBA_INTEGER, gl.UNSIGNED_INT, null);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, t, 0);
  });
  gl.drawBuffers([gl.COLOR_ATTACHMENT0, gl.COLOR_ATTACHMENT1, gl.COLOR_ATTACHMENT2]);
  gl.viewport(0, 0, width, width);
  gl.drawArrays(gl.POINTS, 0, vertexCount);
  const read = (i) => {
    gl.readBuffer(gl.COLOR_ATTACHMENT0 + i);
    const out = new Uint32Array(width * width * 4);
    gl.readPixels(0, 0, width, width, gl.RGBA_INTEGER, gl.UNSIGNED_INT, out);
    return out.subarray(0, vertexCount * 4);
  };
  return { q: read(0), joints: read(1), weightBits: read(2) };
}

/**
 * Conformance vectors in the shader: groups of {ext, codes, grids, weights} (one codec each,
 * valid codes of the 32-bit profile). Integers must be exact; returns the mismatches and the
 * largest weight difference from the binary64 reference.
 */
function gpuConformance(groups) {
  const mismatches = [];
  let maxWeightError = 0, exactWeights = 0, total = 0;
  const float = new Float32Array(1), bits = new Uint32Array(float.buffer);
  for (const group of groups) {
    const codec = codecFromExtension(group.ext), k = codec.influences;
    const gpu = gpuDecode(codec, new Uint32Array(group.codes.map(Number)), new Uint8Array(k));
    group.codes.forEach((code, c) => {
      const grid = k === 1 ? [] : codec.method === 'any' ? Array.from(gpu.q.subarray(4 * c + 1, 4 * c + k)) : Array.from(gpu.q.subarray(4 * c, 4 * c + k));
      if (grid.join() !== group.grids[c].join()) mismatches.push(`${group.ext.method} K=${k} n=${group.ext.n} code ${code}: ${grid} != ${group.grids[c]}`);
      for (let s = 0; s < k; ++s) {
        bits[0] = gpu.weightBits[4 * c + s];
        const ours = float[0];
        bits[0] = parseInt(group.weights[c][s], 16);
        maxWeightError = Math.max(maxWeightError, Math.abs(ours - float[0]));
        if (gpu.weightBits[4 * c + s] === bits[0]) exactWeights++;
        total++;
      }
    });
  }
  return { mismatches: mismatches.slice(0, 10), mismatchCount: mismatches.length, maxWeightError, exactWeights, total };
}

/** Loads url with the plugin (CPU decode) and compares the shader's decode with the CPU's
 *  (rowWidth: tuple texture row length, small to test the row addressing). */
async function gpuReadback(url, rowWidth) {
  const gltf = await load(url, 'cpu');
  const results = [];
  const seen = new Set();
  gltf.scene.traverse((o) => {
    const data = o.isMesh && skinpackData(o);
    if (!data || seen.has(data)) return;
    seen.add(data);
    const gpu = gpuDecode(data.codec, data.words, data.lut, rowWidth);
    const cpuWeightBits = new Uint32Array(data.decoded.weights.buffer);
    let jointMismatches = 0, weightMismatches = 0, maxUlp = 0, first = null;
    for (let i = 0; i < gpu.joints.length; ++i) {
      if (gpu.joints[i] !== data.decoded.joints[i]) { jointMismatches++; first ??= { i, gpu: gpu.joints[i], cpu: data.decoded.joints[i] }; }
      const ulp = Math.abs(gpu.weightBits[i] - cpuWeightBits[i]);
      if (ulp) weightMismatches++;
      maxUlp = Math.max(maxUlp, ulp);
    }
    // q is exact iff float(q) * (1/s) reproduces the decoded weights (grid methods); compare q/s in double.
    let qMismatches = 0;
    if (data.codec.method !== 'any') {
      const s = Number(data.codec.scale);
      for (let i = 0; i < gpu.q.length; ++i) {
        if (i % 4 >= data.codec.influences) continue;
        if (Math.fround(gpu.q[i] * (1 / s)) !== data.decoded.weights[i]) qMismatches++;
      }
    }
    results.push({ mesh: o.name, method: data.codec.method, vertexCount: data.words.length, jointMismatches,
      weightMismatches, maxUlp, qMismatches, first });
  });
  return results;
}

// ---- benchmark: many animated instances, frame times in this page -------------------------------

const benchScenes = new Map();

async function benchScene(url, decode, instances) {
  const key = `${url}|${decode}|${instances}`;
  if (benchScenes.has(key)) return benchScenes.get(key);
  const { clone } = await import('three/addons/utils/SkeletonUtils.js');
  const gltf = await load(url, decode);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2));
  const box = new THREE.Box3().setFromObject(gltf.scene), size = box.getSize(new THREE.Vector3());
  const columns = Math.ceil(Math.sqrt(instances)), mixers = [];
  for (let i = 0; i < instances; ++i) {
    const copy = clone(gltf.scene);
    copy.position.set((i % columns - columns / 2) * size.x * 1.2, 0, -Math.floor(i / columns) * size.z * 1.5);
    copy.traverse((o) => { o.frustumCulled = false; });
    scene.add(copy);
    if (gltf.animations.length) {
      const mixer = new THREE.AnimationMixer(copy);
      mixer.clipAction(gltf.animations[0]).play();
      mixers.push(mixer);
    } else {
      const bones = [];
      copy.traverse((o) => { if (o.isBone) bones.push(o); });
      mixers.push({ setTime: (t) => bones.forEach((b, j) => { b.rotation.z = 0.2 * Math.sin(t * 2 + j + i); }) });
    }
  }
  const extent = columns * Math.max(size.x * 1.2, size.z * 1.5);
  const camera = new THREE.PerspectiveCamera(45, 1, extent / 100, extent * 10);
  camera.position.set(0, extent * 0.6, extent * 0.9);
  camera.lookAt(0, 0, -extent / 3);
  const result = { scene, camera, mixers };
  benchScenes.set(key, result);
  return result;
}

/** Median and mean frame time (ms) of frames renders (each synchronised by a 1-pixel read). */
async function benchmark(url, decode, instances, frames) {
  const { scene, camera, mixers } = await benchScene(url, decode, instances);
  const gl = renderer.getContext(), pixel = new Uint8Array(4), times = [];
  renderer.shadowMap.enabled = false;
  for (let f = -3; f < frames; ++f) {
    const start = performance.now();
    mixers.forEach((m, i) => m.setTime(f / 30 + i * 0.01));
    renderer.render(scene, camera);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    if (f >= 0) times.push(performance.now() - start);
  }
  renderer.shadowMap.enabled = true;
  times.sort((a, b) => a - b);
  const info = { calls: renderer.info.render.calls, triangles: renderer.info.render.triangles };
  return { median: times[times.length >> 1], mean: times.reduce((a, b) => a + b, 0) / times.length, info };
}

window.skinpackTest = { render, loadError, plainSkinWeights, gpuReadback, gpuConformance, benchmark };
window.skinpackTestReady = true;
