"""File sizes and blend-attribute bits of the shared assets: Blender's export, skinpack, gltfpack.

    python3 tests/bench/gltf_sizes.py --skinpack build/native/cli/skinpack --work DIR \
        [--json OUT.json] ASSET.glb...

Every variant is produced and measured in this run (nothing is copied from elsewhere):
  source           the input: Blender's default export (tests/assets/export_blend_assets.py) or
                   the file as shipped (Fox.glb)
  skinpack         skinpack compress --compact (default budget: 32 bits a vertex, OSS)
  skinpack fb      skinpack compress --fallback
  gltfpack         gltfpack defaults (14-bit positions, 12-bit UVs, 8-bit normals; weights u8)
  gltfpack hi      gltfpack -vp 16 -vt 16 -vn 16 (highest vertex precision)
  gltfpack -cc     gltfpack -cc (EXT_meshopt_compression, higher ratio)
  gltfpack+sp      skinpack compress --compact on the gltfpack default output
For each: bytes, bytes after zlib (level 9) and zstd (level 19) of the whole file, stored bits a
vertex of the blend attributes (JOINTS_n + WEIGHTS_n, or packed words + tuple table; from
skinpack info), and the max weight error against the source's weights.

Errors: skinpack outputs are decoded with skinpack decompress and compared vertex by vertex
(joint-matched L-inf). gltfpack reorders and deduplicates vertices, so each of its vertices is
compared with the nearest source vertex (in weights): that error is a lower bound (marked "≥"). gltfpack+sp is compared with the gltfpack output it was made from, and the
gltfpack error is added (a bound for the sum, marked "≤"). -cc files cannot be read without a
meshopt decoder: they hold the same quantised data as the default.
"""
import argparse
import json
import os
import subprocess
import sys
import zlib

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
    z = len(zlib.compress(data, 9))
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


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--skinpack", required=True)
    parser.add_argument("--gltfpack", default="gltfpack")
    parser.add_argument("--work", required=True)
    parser.add_argument("--json")
    parser.add_argument("assets", nargs="+")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    sp = args.skinpack
    rows = []
    for asset in args.assets:
        name = os.path.splitext(os.path.basename(asset))[0]
        w = lambda tag: os.path.join(args.work, "%s.%s.glb" % (name, tag))  # noqa: E731
        reference = skin_influences(asset)
        variants = []

        def add(label, path, error, error_kind=""):
            size, z, zs = compressed_sizes(path)
            bits, vertices = stored_bits(sp, path) if not label.endswith("-cc") else (None, None)
            variants.append({"asset": name, "variant": label, "bytes": size, "zlib": z, "zstd": zs,
                             "blend_bits_per_vertex": bits, "max_weight_error": error, "error_kind": error_kind})

        add("source", asset, 0.0)
        run([sp, "compress", asset, "-o", w("skinpack"), "--compact"])
        run([sp, "decompress", w("skinpack"), "-o", w("skinpack.decoded")])
        sp_error = error_same_order(reference, skin_influences(w("skinpack.decoded")))
        add("skinpack", w("skinpack"), sp_error)
        run([sp, "compress", asset, "-o", w("skinpack_fb"), "--fallback"])
        add("skinpack fb", w("skinpack_fb"), sp_error)
        gp_error = None
        for label, tag, options in [("gltfpack", "gltfpack", []),
                                    ("gltfpack hi", "gltfpack_hi", ["-vp", "16", "-vt", "16", "-vn", "16"]),
                                    ("gltfpack -cc", "gltfpack_cc", ["-cc"])]:
            run([args.gltfpack, "-i", asset, "-o", w(tag)] + options)
            if label == "gltfpack -cc":
                add(label, w(tag), gp_error, "≥")
                continue
            error = error_nearest(reference, skin_influences(w(tag)))
            if label == "gltfpack":
                gp_error = error
            add(label, w(tag), error, "≥")
        run([sp, "compress", w("gltfpack"), "-o", w("gltfpack_sp"), "--compact"])
        run([sp, "decompress", w("gltfpack_sp"), "-o", w("gltfpack_sp.decoded")])
        on_top = error_same_order(skin_influences(w("gltfpack")), skin_influences(w("gltfpack_sp.decoded")))
        add("gltfpack+sp", w("gltfpack_sp"), on_top + gp_error, "≤")
        rows += variants

    print("| asset | variant | bytes | zlib -9 | zstd -19 | blend bits/vertex | max weight error |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for r in rows:
        bits = "%.1f" % r["blend_bits_per_vertex"] if r["blend_bits_per_vertex"] is not None else "n/a"
        error = "%s%.2e" % (r["error_kind"], r["max_weight_error"]) if r["max_weight_error"] else "0"
        print("| %s | %s | %d | %d | %d | %s | %s |" % (r["asset"], r["variant"], r["bytes"], r["zlib"], r["zstd"],
                                                       bits, error))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


main()
