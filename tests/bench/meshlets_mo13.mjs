// meshlets_mo13.mjs - meshoptimizer's current clusterizer (npm `meshoptimizer`, pinned in
// tools/package-lock.json; WebAssembly in node) on one mesh exported by
// tests/meshlets/export_mesh_data.py, for tests/bench/meshlets_bench.c, which starts this script
// in the same run and analyses the meshlets exactly as it analyses its own.
//
//   node meshlets_mo13.mjs MESH.spmd MAX_VERTICES MAX_TRIANGLES REPS OUT.bin
//
// Runs MeshoptClusterizer.buildMeshlets (cone_weight 0) REPS times and writes the last result
// to OUT.bin: u32 meshlet count, then per meshlet u32 vertex_offset, triangle_offset,
// vertex_count, triangle_count, then u32 vertex entries and the vertex indices. Prints one JSON
// line: {"version", "meshlets", "ms"} with ms the least CPU time of the process (user + system,
// process.cpuUsage: node has no per-thread CPU clock) over one build; the build includes
// copying into WebAssembly memory and meshopt_optimizeMeshlet on each meshlet, as the npm
// wrapper does. CPU time, not wall clock: on a machine shared by several jobs a few-millisecond
// build's wall time depends on how often it is preempted.
import { readFileSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const tools = join(dirname(fileURLToPath(import.meta.url)), '..', '..', 'tools', 'node_modules');
const { MeshoptClusterizer } = await import(join(tools, 'meshoptimizer', 'index.js'));
const version = JSON.parse(readFileSync(join(tools, 'meshoptimizer', 'package.json'), 'utf8')).version;

function fail(message) {
	console.error(`Error: meshlets_mo13: ${message}`);
	process.exit(1);
}

function loadMesh(path) {
	const file = readFileSync(path);
	if (file.length < 24 || file.toString('latin1', 0, 4) !== 'SPMD') fail(`${path}: not an SPMD file`);
	const header = new Uint32Array(file.buffer.slice(file.byteOffset + 4, file.byteOffset + 24));
	const [formatVersion, vertexCount, indexCount] = header;
	if (formatVersion !== 1) fail(`${path}: SPMD version ${formatVersion}, expected 1`);
	const positionBytes = vertexCount * 12, indexBytes = indexCount * 4;
	if (file.length < 24 + positionBytes + indexBytes) fail(`${path}: truncated`);
	const copy = (offset, bytes) => file.buffer.slice(file.byteOffset + offset, file.byteOffset + offset + bytes);
	return {
		positions: new Float32Array(copy(24, positionBytes)),
		indices: new Uint32Array(copy(24 + positionBytes, indexBytes)),
	};
}

const [path, maxVerticesText, maxTrianglesText, repsText, outPath] = process.argv.slice(2);
if (!outPath) fail('usage: node meshlets_mo13.mjs MESH.spmd MAX_VERTICES MAX_TRIANGLES REPS OUT.bin');
const maxVertices = Number(maxVerticesText), maxTriangles = Number(maxTrianglesText), reps = Number(repsText);
if (!(maxVertices >= 3 && maxTriangles >= 1 && reps >= 1)) fail(`bad limits ${maxVerticesText}/${maxTrianglesText}/${repsText}`);

await MeshoptClusterizer.ready;
const mesh = loadMesh(path);
let result = null, best = Infinity;
for (let i = 0; i < reps; ++i) {
	const start = process.cpuUsage();
	result = MeshoptClusterizer.buildMeshlets(mesh.indices, mesh.positions, 3, maxVertices, maxTriangles, 0.0);
	const used = process.cpuUsage(start);
	const ms = (used.user + used.system) / 1e3;
	best = Math.min(best, ms);
}

const count = result.meshletCount;
const out = new Uint32Array(1 + count * 4 + 1 + result.vertices.length);
out[0] = count;
out.set(result.meshlets.subarray(0, count * 4), 1);
out[1 + count * 4] = result.vertices.length;
out.set(result.vertices, 2 + count * 4);
writeFileSync(outPath, out);
console.log(JSON.stringify({ version, meshlets: count, ms: best }));
