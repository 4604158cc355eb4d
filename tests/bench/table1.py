#!/usr/bin/env python3
"""The paper's Table 1 (bone-index compression) for glTF files, with and without don't-care
tuple sharing, from `skinpack compress --json`. Prints a Markdown table; asserts nothing.

usage: table1.py SKINPACK FILE.glb [FILE.glb ...]
"""
import json
import math
import os
import subprocess
import sys
import tempfile


def compress(skinpack, path, extra):
    with tempfile.TemporaryDirectory() as work:
        out = os.path.join(work, "out.glb")
        run = subprocess.run([skinpack, "compress", path, "-o", out, "--json"] + extra,
                             check=True, capture_output=True, text=True)
        return json.loads(run.stdout)["primitives"]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    skinpack = sys.argv[1]
    print("| mesh | V | joints | raw [bpv] | tuples exact | tuples shared | tuple idx [bpv] | LUT [bpv] | saved [bpv] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for path in sys.argv[2:]:
        exact = compress(skinpack, path, ["--exact-tuples"])
        shared = compress(skinpack, path, [])
        for e, s in zip(exact, shared):
            raw = 4 * math.ceil(math.log2(max(2, s["joints"])))
            saved = (e["tuple_bits"] + e["lut_bits_per_vertex"]) - (s["tuple_bits"] + s["lut_bits_per_vertex"])
            name = os.path.splitext(os.path.basename(path))[0]
            if len(shared) > 1:
                name += f" #{s['mesh']}.{s['primitive']}"
            print(f"| {name} | {s['vertices']} | {s['joints']} | {raw} | {e['unique_tuples']} | "
                  f"{s['unique_tuples']} | {e['tuple_bits']} → {s['tuple_bits']} | "
                  f"{e['lut_bits_per_vertex']:.2f} → {s['lut_bits_per_vertex']:.2f} | {saved:.2f} |")


if __name__ == "__main__":
    main()
