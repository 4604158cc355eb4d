#!/usr/bin/env python3
"""Runs `skinpack bench --json` and prints the Markdown section of docs/benchmarks.md.

usage: core_bench_report.py SKINPACK [--vertices N]
Ratios are to memcpy of the same input bytes, measured in the same run; nothing is asserted.
"""
import json
import platform
import subprocess
import sys


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    args = [sys.argv[1], "bench", "--json"] + sys.argv[2:]
    data = json.loads(subprocess.run(args, check=True, capture_output=True, text=True).stdout)
    memcpy = data["memcpy_vertices_per_s"]
    print(f"Machine: {platform.processor() or platform.machine()}, {data['vertices']} vertices, "
          f"single thread, best of 5.\n")
    print(f"- memcpy of the input (4 u8 joints + 4 float weights, 20 B/vertex): "
          f"{memcpy / 1e6:.0f} M vertices/s")
    print(f"- tuple table build (hash, don't-care merging): "
          f"{data['lut_build_vertices_per_s'] / 1e6:.1f} M vertices/s "
          f"({data['lut_build_vertices_per_s'] / memcpy:.3f}x memcpy)\n")
    print("| method | K | bits | encode M/s | encode / memcpy | decode M/s | decode / memcpy |")
    print("|---|---|---|---|---|---|---|")
    for c in data["codecs"]:
        print(f"| {c['method']} | {c['influences']} | {c['bits']} | "
              f"{c['encode_vertices_per_s'] / 1e6:.1f} | {c['encode_ratio']:.3f} | "
              f"{c['decode_vertices_per_s'] / 1e6:.1f} | {c['decode_ratio']:.3f} |")


if __name__ == "__main__":
    main()
