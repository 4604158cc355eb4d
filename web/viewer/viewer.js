// viewer.js - the Skinpack viewer: open or drop a .glb, play its animations, see per-mesh stats,
// switch GPU/CPU decode, original/decoded weights (fallback files) and colour by weight error.
// URL parameters (also for scripted screenshots): ?file=URL&decode=gpu|cpu&weights=original&shade=error&time=T
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { SkinpackGLTFPlugin, skinpackData, skinpackMaterial } from '../src/SkinpackGLTFPlugin.js';
import { SKINPACK_EXTENSION } from '../src/decode.js';
import { accessorBytes, weightError } from '../src/stats.js';

const params = new URLSearchParams(location.search);
const state = {
  buffer: null, name: '', decode: params.get('decode') === 'cpu' ? 'cpu' : 'gpu',
  weights: params.get('weights') === 'original' ? 'original' : 'decoded',
  shade: params.get('shade') === 'error' ? 'error' : 'material', time: Number(params.get('time') || 0),
  playing: !params.has('time'), gltf: null, mixer: null, action: null, error: null, loads: 0,
};
const $ = (id) => document.getElementById(id);

const stage = $('stage');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.shadowMap.enabled = true;
stage.prepend(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1a1d24);
const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = true;
scene.add(new THREE.HemisphereLight(0xffffff, 0x30343c, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.castShadow = true;
sun.shadow.mapSize.set(2048, 2048);
scene.add(sun, sun.target);
const ground = new THREE.Mesh(new THREE.CircleGeometry(1, 64), new THREE.MeshStandardMaterial({ color: 0x2a2e37, roughness: 0.95 }));
ground.rotation.x = -Math.PI / 2;
ground.receiveShadow = true;
scene.add(ground);
let previousFrame = performance.now();

function setStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

function loadGltf(buffer) {
  const loader = new GLTFLoader();
  loader.setMeshoptDecoder(MeshoptDecoder); // gltfpack -cc and skinpack compress --meshopt files
  if (state.weights === 'decoded') loader.register((parser) => new SkinpackGLTFPlugin(parser, { decode: state.decode }));
  return loader.parseAsync(buffer.slice(0), '');
}

function frame(object) {
  const box = new THREE.Box3().setFromObject(object);
  const center = box.getCenter(new THREE.Vector3()), size = box.getSize(new THREE.Vector3()).length() || 1;
  controls.target.copy(center);
  camera.near = size / 200; camera.far = size * 20;
  camera.position.copy(center).add(new THREE.Vector3(0.7, 0.35, 1).normalize().multiplyScalar(size * 1.15));
  camera.updateProjectionMatrix();
  ground.scale.setScalar(size * 1.5);
  ground.position.set(center.x, box.min.y, center.z);
  sun.position.copy(center).add(new THREE.Vector3(size, size * 2, size * 0.6));
  sun.target.position.copy(center);
  Object.assign(sun.shadow.camera, { left: -size, right: size, top: size, bottom: -size, near: size / 100, far: size * 6 });
  sun.shadow.camera.updateProjectionMatrix();
}

// Heat map of the per-vertex error, 0 (blue) to the codec's bound (red).
function errorColours(perVertex, bound) {
  const colours = new Float32Array(perVertex.length * 3), colour = new THREE.Color();
  for (let v = 0; v < perVertex.length; ++v) {
    const t = Math.min(perVertex[v] / bound, 1);
    colour.setHSL((1 - t) * 0.66, 1, 0.5, THREE.SRGBColorSpace);
    colour.toArray(colours, v * 3);
  }
  return new THREE.BufferAttribute(colours, 3);
}

function meshStats(mesh, json) {
  const data = skinpackData(mesh);
  const association = state.gltf.parser.associations.get(mesh);
  const primitive = association && json.meshes[association.meshes].primitives[association.primitives];
  const ext = primitive && primitive.extensions && primitive.extensions[SKINPACK_EXTENSION];
  const vertices = mesh.geometry.getAttribute('position').count;
  const skinAccessors = primitive ? Object.keys(primitive.attributes).filter((n) => /^(JOINTS|WEIGHTS)_\d+$/.test(n)) : [];
  const beforeBytes = skinAccessors.reduce((sum, n) => sum + accessorBytes(json.accessors[primitive.attributes[n]]), 0);
  const stats = { name: mesh.name || '(unnamed)', vertices, beforeBits: (beforeBytes * 8) / vertices, ext, data };
  if (data) {
    const lutBytes = data.lut.byteLength;
    stats.afterBits = ext.tupleBits + ext.weightBits + (lutBytes * 8) / vertices;
    stats.bound = ext.maxError || data.codec.maxError;
    if (data.original) stats.error = weightError(data.decoded, data.original.skinIndex, data.original.skinWeight);
  }
  const uploaded = ['skinIndex', 'skinWeight', 'skinpackWord'].map((n) => mesh.geometry.getAttribute(n)).filter(Boolean);
  stats.gpuBytes = uploaded.reduce((sum, a) => sum + a.array.byteLength, 0) +
                   (data && data.uniforms ? data.uniforms.skinpackTuples.value.image.data.byteLength : 0);
  return stats;
}

function row(label, value, dim = false) {
  return `<tr><td class="dim">${label}</td><td${dim ? ' class="dim"' : ''}>${value}</td></tr>`;
}

function renderStats(list) {
  $('meshes').innerHTML = list.map((s) => {
    const path = s.data ? s.data.info.decode : 'plain';
    const label = s.data ? `${path.toUpperCase()} decode` : s.ext ? 'original weights' : 'not packed';
    const tag = `<span class="tag ${path}">${label}</span>`;
    const lines = [row('vertices', s.vertices.toLocaleString())];
    if (s.data) {
      lines.push(row('codec', `${s.ext.method} n=${s.ext.n}, K=${s.ext.influences}, ${s.ext.weightBits}+${s.ext.tupleBits} bits`));
      lines.push(row('bits / vertex', `${s.beforeBits.toFixed(1)} → <b>${s.afterBits.toFixed(1)}</b>`));
      lines.push(row('max weight error', s.error ? `${s.error.max.toExponential(2)} <span class="dim">(bound ${s.bound.toExponential(2)})</span>`
                                                  : `≤ ${s.bound.toExponential(2)} <span class="dim">(bound; compact: no original)</span>`));
    } else if (s.beforeBits) {
      lines.push(row('bits / vertex', `${s.beforeBits.toFixed(1)}`));
    }
    lines.push(row('GPU bytes for the skin', `${s.gpuBytes.toLocaleString()} <span class="dim">(${((s.gpuBytes * 8) / s.vertices).toFixed(1)} bits/v)</span>`));
    const note = s.data && s.data.info.reason && state.decode === 'gpu' ? `<div class="note">CPU fallback: ${s.data.info.reason}</div>` : '';
    return `<div class="mesh"><div class="name"><span>${s.name}</span>${tag}</div><table>${lines.join('')}</table>${note}</div>`;
  }).join('') || '<div class="dim">No skinned mesh.</div>';
}

function applyErrorShading(list) {
  let shown = false;
  for (const s of list) {
    if (!s.error) continue;
    const mesh = s.data && state.gltf.scene.getObjectById(s.meshId);
    mesh.geometry.setAttribute('color', errorColours(s.error.perVertex, s.bound));
    const material = new THREE.MeshLambertMaterial({ vertexColors: true });
    mesh.material = s.data.uniforms ? skinpackMaterial(mesh, material) : material;
    $('legend-max').textContent = s.bound.toExponential(1);
    shown = true;
  }
  $('legend').hidden = !shown;
}

function setupAnimation(gltf) {
  const clips = gltf.animations;
  $('clip').innerHTML = clips.map((c, i) => `<option value="${i}">${c.name || `clip ${i}`}</option>`).join('');
  for (const id of ['clip', 'play', 'time']) $(id).disabled = clips.length === 0;
  state.mixer = clips.length ? new THREE.AnimationMixer(gltf.scene) : null;
  playClip(Math.min(Number($('clip').value) || 0, clips.length - 1));
}

function playClip(index) {
  if (!state.mixer || index < 0) return;
  state.mixer.stopAllAction();
  state.action = state.mixer.clipAction(state.gltf.animations[index]).play();
  $('time').max = state.action.getClip().duration;
  state.mixer.setTime(state.time);
}

async function show() {
  if (!state.buffer) return;
  const load = ++state.loads;
  setStatus(`Loading ${state.name}…`);
  let gltf;
  try {
    gltf = await loadGltf(state.buffer);
  } catch (error) {
    if (load !== state.loads) return;
    state.error = String(error.message || error);
    if (state.gltf) scene.remove(state.gltf.scene);
    state.gltf = null;
    $('meshes').innerHTML = '';
    setStatus(state.error, true);
    return;
  }
  if (load !== state.loads) return;
  if (state.gltf) scene.remove(state.gltf.scene);
  state.gltf = gltf;
  state.error = null;
  scene.add(gltf.scene);
  gltf.scene.traverse((o) => { if (o.isMesh) { o.castShadow = true; o.frustumCulled = false; } });
  frame(gltf.scene);
  $('drop').classList.add('hidden');
  const json = gltf.parser.json;
  const list = [];
  gltf.scene.traverse((o) => { if (o.isSkinnedMesh) list.push({ ...meshStats(o, json), meshId: o.id }); });
  const packed = list.some((s) => s.ext), fallback = list.some((s) => s.data && s.data.original);
  const original = state.weights === 'original';
  $('weights-original').disabled = !original && !fallback;
  $('shade-error').disabled = original || !fallback;
  if (state.shade === 'error' && !original) applyErrorShading(list); else $('legend').hidden = true;
  renderStats(list);
  $('title').textContent = state.name;
  $('summary').textContent = packed ? `${SKINPACK_EXTENSION}: ${(json.extensionsRequired || []).includes(SKINPACK_EXTENSION) ? 'compact' : 'fallback'} file` +
    (original ? ' — showing the original JOINTS_0/WEIGHTS_0 (plain three.js)' : '') : 'no packed skin (plain glTF)';
  setupAnimation(gltf);
  setStatus(`${state.name}: ${list.length} skinned mesh(es), ${gltf.animations.length} animation(s)`);
}

function openBuffer(buffer, name) {
  state.buffer = buffer;
  state.name = name;
  state.time = 0;
  return show();
}

function bindSegments(attribute, key) {
  document.querySelectorAll(`[data-${attribute}]`).forEach((button) => {
    button.classList.toggle('active', button.dataset[attribute] === state[key]);
    button.addEventListener('click', () => {
      if (button.disabled) return;
      state[key] = button.dataset[attribute];
      document.querySelectorAll(`[data-${attribute}]`).forEach((b) => b.classList.toggle('active', b === button));
      show();
    });
  });
}

bindSegments('decode', 'decode');
bindSegments('weights', 'weights');
bindSegments('shade', 'shade');
$('file').addEventListener('change', async (e) => {
  const file = e.target.files[0];
  if (file) openBuffer(await file.arrayBuffer(), file.name);
});
window.addEventListener('dragover', (e) => { e.preventDefault(); $('drop').classList.add('over'); });
window.addEventListener('dragleave', () => $('drop').classList.remove('over'));
window.addEventListener('drop', async (e) => {
  e.preventDefault();
  $('drop').classList.remove('over');
  const file = e.dataTransfer.files[0];
  if (file) openBuffer(await file.arrayBuffer(), file.name);
});
$('clip').addEventListener('change', () => playClip(Number($('clip').value)));
$('play').addEventListener('click', () => { state.playing = !state.playing; $('play').textContent = state.playing ? 'Pause' : 'Play'; });
$('time').addEventListener('input', () => { state.playing = false; $('play').textContent = 'Play'; state.time = Number($('time').value); state.mixer?.setTime(state.time); });
$('play').textContent = state.playing ? 'Pause' : 'Play';

let frames = 0, last = performance.now();
function tick() {
  const now = performance.now(), dt = Math.min((now - previousFrame) / 1000, 0.1);
  previousFrame = now;
  const width = stage.clientWidth, height = stage.clientHeight;
  if (renderer.domElement.width !== Math.floor(width * renderer.getPixelRatio())) {
    renderer.setSize(width, height, false);
    camera.aspect = width / Math.max(height, 1);
    camera.updateProjectionMatrix();
  }
  if (state.mixer && state.playing) {
    state.time = (state.time + dt) % state.action.getClip().duration;
    state.mixer.setTime(state.time);
    $('time').value = state.time;
  }
  controls.update();
  renderer.render(scene, camera);
  ++frames;
  if (now - last > 500) {
    const info = renderer.info;
    $('renderer').textContent = `${((frames * 1000) / (now - last)).toFixed(1)} fps   ${info.render.calls} draws   ${info.render.triangles.toLocaleString()} triangles\n` +
      `${info.memory.geometries} geometries   ${info.memory.textures} textures\n${renderer.capabilities.isWebGL2 ? 'WebGL2' : 'WebGL'}`;
    last = now;
    frames = 0;
  }
  requestAnimationFrame(tick);
}
requestAnimationFrame(tick);

window.skinpackViewer = { state, show, openBuffer };
if (params.get('file')) {
  fetch(params.get('file')).then((r) => { if (!r.ok) throw new Error(`${params.get('file')}: HTTP ${r.status}`); return r.arrayBuffer(); })
    .then((b) => openBuffer(b, params.get('file').split('/').pop())).then(() => { state.time = Number(params.get('time') || 0); state.mixer?.setTime(state.time); $('time').value = state.time; })
    .catch((e) => setStatus(String(e.message || e), true));
}
