"""Whole-file sizes, GPU-resident skin bits and weight errors: original, gltfpack, Draco, skinpack.

    python3 tests/bench/gltf_sizes.py --skinpack build/native/cli/skinpack --tools tools \
        --work DIR [--json OUT.json] ASSET.glb...

Every variant is produced and measured in this run (docs/benchmarks-gltf.md):
  original         the input: Blender's default export (tests/assets/export_blend_assets.py) or
                   the file as shipped (Fox.glb)
  gltfpack 1.3     gltfpack -cc (npm gltfpack 1.3: quantisation + EXT_meshopt_compression), and
                   gltfpack -noq -cc (no quantisation: float weights)
  Draco            gltf-transform draco (glTF-Transform 4.5, its default Draco settings)
  skinpack         skinpack compress --compact (default budget: 32 bits a vertex, OSS), and with
                   --meshopt (packed words and tuple table meshopt-compressed where that pays)
  gltfpack+sp      gltfpack -cc, then skinpack compress --compact, without and with --meshopt;
                   gltfpack -noq -cc, then skinpack compress --compact --meshopt
For each: bytes, bytes after gzip -9 and zstd -19 of the whole file, the skin's GPU-resident
bits a vertex (JOINTS_n + WEIGHTS_n as their accessors decode, or packed words + tuple table;
from skinpack info on the file, or on its decoded copy for Draco), and the max weight error
against the original's weights. A second table gives, for the --meshopt rows, the bytes of the
packed words + tuple table and what they take in the file (compress --json).

Errors: skinpack is decoded with skinpack decompress and compared vertex by vertex (exact).
gltfpack and Draco merge and reorder vertices, so each of their vertices is compared with the
nearest original vertex (in weights): a lower bound (marked "≥"). gltfpack+sp is skinpack's exact
error against the gltfpack file's weights plus that lower bound (marked "≈").
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


class Asset:
    """One asset's rows, all measured in this run."""

    def __init__(self, args, asset, rows):
        self.args, self.asset, self.rows = args, asset, rows
        self.name = os.path.splitext(os.path.basename(asset))[0]
        self.reference = skin_influences(asset)

    def path(self, tag):
        return os.path.join(self.args.work, "%s.%s.glb" % (self.name, tag))

    def add(self, label, path, bits_path, error, error_kind="", report=None):
        size, z, zs = compressed_sizes(path)
        bits, _ = stored_bits(self.args.skinpack, bits_path)
        row = {"asset": self.name, "variant": label, "bytes": size, "gzip": z, "zstd": zs,
               "gpu_bits_per_vertex": bits, "max_weight_error": error, "error_kind": error_kind}
        if report:  # skinpack compress --json: the packed words + tuple table, as the GPU holds them and as stored
            unique = [p for p in report["primitives"] if p["shared_with"] < 0]
            row["packed_bytes"] = sum(p["packed_bytes"] for p in unique)
            row["stored_packed_bytes"] = sum(p["stored_packed_bytes"] for p in unique)
        self.rows.append(row)

    def gltfpack(self, label, tag, flags):
        """gltfpack with flags; returns (file, its plain decode, its error lower bound)."""
        out = self.path(tag)
        run(gltfpack_command(self.args) + ["-i", self.asset, "-o", out] + flags)
        node_tool(self.args, "meshopt_unpack.mjs", out, out + ".plain.glb")
        error = error_nearest(self.reference, skin_influences(out + ".plain.glb"))
        self.add(label, out, out, error, "≥")
        return out, error

    def skinpack(self, label, source, tag, flags, source_error=None):
        """skinpack compress --compact flags on source; the error is exact against the original, or
        (source_error given: a gltfpack file) against source's weights plus source_error."""
        out = self.path(tag)
        report = json.loads(run([self.args.skinpack, "compress", source, "-o", out, "--compact", "--json"] + flags))
        run([self.args.skinpack, "decompress", out, "-o", out + ".decoded.glb"])
        if source_error is None:
            error = error_same_order(self.reference, skin_influences(out + ".decoded.glb"))
            self.add(label, out, out, error, report=report)
            return
        node_tool(self.args, "meshopt_unpack.mjs", out + ".decoded.glb", out + ".decoded.plain.glb")
        on_top = error_same_order(skin_influences(source + ".plain.glb"), skin_influences(out + ".decoded.plain.glb"))
        self.add(label, out, out, on_top + source_error, "≈", report=report)


def gltfpack_command(args):
    return [args.node, os.path.join(args.tools, "node_modules", "gltfpack", "cli.js")]


def measure(args, asset, rows):
    a = Asset(args, asset, rows)
    transform = [args.node, os.path.join(args.tools, "node_modules", "@gltf-transform", "cli", "bin", "cli.js")]
    a.add("original", asset, asset, 0.0)
    gltfpack, gp_error = a.gltfpack("gltfpack 1.3 -cc", "gltfpack", ["-cc"])
    noq, noq_error = a.gltfpack("gltfpack 1.3 -noq -cc", "gltfpack_noq", ["-noq", "-cc"])
    run(transform + ["draco", asset, a.path("draco")])
    node_tool(args, "gltf_plain.mjs", a.path("draco"), a.path("draco.plain"))
    a.add("Draco (glTF-Transform)", a.path("draco"), a.path("draco.plain"),
          error_nearest(a.reference, skin_influences(a.path("draco.plain"))), "≥")
    a.skinpack("skinpack", asset, "skinpack", [])
    a.skinpack("skinpack --meshopt", asset, "skinpack_meshopt", ["--meshopt"])
    a.skinpack("gltfpack -cc, then skinpack", gltfpack, "gltfpack_sp", [], gp_error)
    a.skinpack("gltfpack -cc, then skinpack --meshopt", gltfpack, "gltfpack_sp_meshopt", ["--meshopt"], gp_error)
    a.skinpack("gltfpack -noq -cc, then skinpack --meshopt", noq, "gltfpack_noq_sp_meshopt", ["--meshopt"], noq_error)


def print_tables(rows):
    print("| asset | variant | bytes | gzip -9 | zstd -19 | GPU skin bits/vertex | max weight error |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for r in rows:
        error = "%s%.2e" % (r["error_kind"], r["max_weight_error"]) if r["max_weight_error"] else "0"
        print("| %s | %s | %d | %d | %d | %.1f | %s |" % (r["asset"], r["variant"], r["bytes"], r["gzip"], r["zstd"],
                                                        r["gpu_bits_per_vertex"], error))
    print()
    print("| asset | variant | packed words + tuple table | stored with --meshopt | saved |")
    print("|---|---|---:|---:|---:|")
    for r in rows:
        if r["variant"].endswith("--meshopt"):
            print("| %s | %s | %d | %d | %d |" % (r["asset"], r["variant"], r["packed_bytes"], r["stored_packed_bytes"],
                                                r["packed_bytes"] - r["stored_packed_bytes"]))


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
    rows = []
    for asset in args.assets:
        measure(args, asset, rows)
    print_tables(rows)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


main()
