"""Whole-file sizes, GPU-resident skin bits and weight errors: original, gltfpack, Draco, skinpack.

    python3 tests/bench/gltf_sizes.py --skinpack build/native/cli/skinpack --tools tools \
        --work DIR [--json OUT.json] ASSET.glb...

Every variant is produced and measured in this run (docs/benchmarks-gltf.md):
  original         the input: Blender's default export (tests/assets/export_blend_assets.py) or
                   the file as shipped (Fox.glb)
  gltfpack 1.3     gltfpack -cc (npm gltfpack 1.3: quantisation + EXT_meshopt_compression)
  Draco            gltf-transform draco (glTF-Transform 4.5, its default Draco settings)
  skinpack         skinpack compress --compact (default budget: 32 bits a vertex, OSS)
  gltfpack+sp      gltfpack -cc, then skinpack compress --compact
For each: bytes, bytes after gzip -9 and zstd -19 of the whole file, the skin's GPU-resident
bits a vertex (JOINTS_n + WEIGHTS_n as their accessors decode, or packed words + tuple table;
from skinpack info on the file, or on its decoded copy for Draco), and the max weight error
against the original's weights. A last line per asset measures what meshopt-compressing
skinpack's packed words would save (npm meshoptimizer's encodeVertexBuffer on them).

Errors: skinpack is decoded with skinpack decompress and compared vertex by vertex (exact).
gltfpack and Draco merge and reorder vertices, so each of their vertices is compared with the
nearest original vertex (in weights): a lower bound (marked "≥"). gltfpack+sp is skinpack's exact
error against the gltfpack weights plus that lower bound (marked "≈").
"""
import argparse
import json
import os
import subprocess
import sys
import gzip

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cli"))
import gltf_read  # noqa: E402


def run(cmd):
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit("FAILED: %s\n%s%s" % (" ".join(cmd), result.stdout, result.stderr))
    return result.stdout


def compressed_sizes(path):
    with open(path, "rb") as f:
        data = f.read()
    z = len(gzip.compress(data, 9, mtime=0))
    zs = len(subprocess.run(["zstd", "-19", "-c", "-q", path], capture_output=True, check=True).stdout)
    return len(data), z, zs


def stored_bits(skinpack, path):
    info = json.loads(run([skinpack, "info", path, "--json"]))
    return info["bits_per_vertex"], info["vertices"]


def skin_influences(path):
    doc = gltf_read.Gltf(path)
    out = []
    for _, _, prim in doc.primitives():
        inf = doc.influences(prim)
        if inf is not None and "bufferView" in doc.json["accessors"][prim["attributes"]["JOINTS_0"]]:
            out.append([{j: w / sum(v.values()) for j, w in v.items()} for v in inf])
    return out


def vertex_error(a, b):
    return max(abs(a.get(j, 0.0) - b.get(j, 0.0)) for j in set(a) | set(b))


def error_same_order(reference, decoded):
    worst = 0.0
    for ref_prim, dec_prim in zip(reference, decoded):
        for a, b in zip(ref_prim, dec_prim):
            worst = max(worst, vertex_error(a, b))
    return worst


def error_nearest(reference, decoded):
    """Max over decoded vertices of a lower bound of their error: the distance to the nearest
    source vertex. Only source vertices that have the decoded vertex's heaviest joint j need a
    look: any other one is at least w(j) away."""
    by_joint = {}
    for prim in reference:
        for v in prim:
            for j in v:
                by_joint.setdefault(j, []).append(v)
    worst = 0.0
    for prim in decoded:
        for v in prim:
            heaviest = max(v, key=lambda j: v[j])
            nearest = min([vertex_error(v, c) for c in by_joint.get(heaviest, [])] + [v[heaviest]])
            worst = max(worst, nearest)
    return worst


def node_tool(args, script, *paths):
    run([args.node, os.path.join(args.tools, script)] + list(paths))


def packed_words_meshopt(args, path):
    """(raw bytes, meshopt-encoded bytes) of the packed words of every primitive of path."""
    script = os.path.join(args.work, "words_meshopt.mjs")
    with open(script, "w") as f:
        f.write(WORDS_MESHOPT % json.dumps(os.path.join(os.path.abspath(args.tools), "node_modules", "meshoptimizer",
                                                        "index.js")))
    return json.loads(run([args.node, script, path]))


WORDS_MESHOPT = """
import { readFileSync } from 'node:fs';
const { MeshoptEncoder } = await import(%s);
await MeshoptEncoder.ready;
const file = readFileSync(process.argv[2]);
const n = file.readUInt32LE(12), json = JSON.parse(file.subarray(20, 20 + n));
const bin = file.subarray(20 + n + 8);
const seen = new Set();
let raw = 0, encoded = 0;
for (const mesh of json.meshes) for (const p of mesh.primitives) {
  const e = p.extensions && p.extensions.SKINPACK_packed_skin;
  if (!e || seen.has(e.vertices)) continue;
  seen.add(e.vertices);
  const a = json.accessors[e.vertices], v = json.bufferViews[a.bufferView];
  const words = bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength);
  raw += v.byteLength;
  encoded += MeshoptEncoder.encodeVertexBuffer(new Uint8Array(words), a.count, v.byteLength / a.count).length;
}
console.log(JSON.stringify([raw, encoded]));
"""


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--node", default="node")
    parser.add_argument("--tools", required=True, help="tools/ with node_modules (npm ci)")
    parser.add_argument("--work", required=True)
    parser.add_argument("--json")
    parser.add_argument("assets", nargs="+")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    sp = args.skinpack
    gltfpack = [args.node, os.path.join(args.tools, "node_modules", "gltfpack", "cli.js")]
    transform = [args.node, os.path.join(args.tools, "node_modules", "@gltf-transform", "cli", "bin", "cli.js")]
    rows = []
    for asset in args.assets:
        name = os.path.splitext(os.path.basename(asset))[0]
        w = lambda tag: os.path.join(args.work, "%s.%s.glb" % (name, tag))  # noqa: E731
        reference = skin_influences(asset)

        def add(label, path, bits_path, error, error_kind=""):
            size, z, zs = compressed_sizes(path)
            bits, _ = stored_bits(sp, bits_path)
            rows.append({"asset": name, "variant": label, "bytes": size, "gzip": z, "zstd": zs,
                         "gpu_bits_per_vertex": bits, "max_weight_error": error, "error_kind": error_kind})

        add("original", asset, asset, 0.0)
        run(gltfpack + ["-i", asset, "-o", w("gltfpack"), "-cc"])
        node_tool(args, "meshopt_unpack.mjs", w("gltfpack"), w("gltfpack.plain"))
        gp_error = error_nearest(reference, skin_influences(w("gltfpack.plain")))
        add("gltfpack 1.3 -cc", w("gltfpack"), w("gltfpack"), gp_error, "≥")
        run(transform + ["draco", asset, w("draco")])
        node_tool(args, "gltf_plain.mjs", w("draco"), w("draco.plain"))
        add("Draco (glTF-Transform)", w("draco"), w("draco.plain"),
            error_nearest(reference, skin_influences(w("draco.plain"))), "≥")
        run([sp, "compress", asset, "-o", w("skinpack"), "--compact"])
        run([sp, "decompress", w("skinpack"), "-o", w("skinpack.decoded")])
        add("skinpack", w("skinpack"), w("skinpack"), error_same_order(reference, skin_influences(w("skinpack.decoded"))))
        run([sp, "compress", w("gltfpack"), "-o", w("gltfpack_sp"), "--compact"])
        run([sp, "decompress", w("gltfpack_sp"), "-o", w("gltfpack_sp.decoded")])
        node_tool(args, "meshopt_unpack.mjs", w("gltfpack_sp.decoded"), w("gltfpack_sp.decoded.plain"))
        on_top = error_same_order(skin_influences(w("gltfpack.plain")), skin_influences(w("gltfpack_sp.decoded.plain")))
        add("gltfpack -cc, then skinpack", w("gltfpack_sp"), w("gltfpack_sp"), on_top + gp_error, "≈")
        raw, encoded = packed_words_meshopt(args, w("gltfpack_sp"))
        rows[-1]["packed_words_bytes"], rows[-1]["packed_words_meshopt_bytes"] = raw, encoded

    print("| asset | variant | bytes | gzip -9 | zstd -19 | GPU skin bits/vertex | max weight error |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for r in rows:
        error = "%s%.2e" % (r["error_kind"], r["max_weight_error"]) if r["max_weight_error"] else "0"
        print("| %s | %s | %d | %d | %d | %.1f | %s |" % (r["asset"], r["variant"], r["bytes"], r["gzip"], r["zstd"],
                                                        r["gpu_bits_per_vertex"], error))
    print()
    print("| asset | packed words (gltfpack+sp) | meshopt-encoded | saved | gltfpack+sp with it | gltfpack alone |")
    print("|---|---:|---:|---:|---:|---:|")
    by = {(r["asset"], r["variant"]): r for r in rows}
    for r in rows:
        if "packed_words_bytes" not in r:
            continue
        saved = r["packed_words_bytes"] - r["packed_words_meshopt_bytes"]
        print("| %s | %d | %d | %d | %d | %d |" % (r["asset"], r["packed_words_bytes"], r["packed_words_meshopt_bytes"],
                                                   saved, r["bytes"] - saved, by[(r["asset"], "gltfpack 1.3 -cc")]["bytes"]))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


main()
