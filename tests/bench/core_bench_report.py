#!/usr/bin/env python3
"""Runs `skinpack bench --json` once per vector path and prints the Markdown section of
docs/benchmarks.md.

usage: core_bench_report.py SKINPACK [--vertices N] [--repeats R] [--isa scalar,avx2,avx512] [--all-methods]
       core_bench_report.py --from-json A.json [B.json ...] [--all-methods]
Rates are medians of R runs; ratios are to a memcpy of the 4 float weights (16 B/vertex)
measured in the same run (the same process, just before each repetition): the best-of ratio
(fastest copy / fastest run, the least disturbed on a shared machine; marked against the targets)
and the median of the per-repetition ratios. Nothing is asserted.
"""
import json
import platform
import subprocess
import sys

TARGET = 0.5  # issue 14: every OSS row >= 0.5x memcpy with AVX2 and with AVX-512
SCALAR_ENCODE = 1 / 7.8  # issue 14: scalar at least as fast as the authors' scalar code
SCALAR_DECODE = 1 / 44.0
ALL_METHODS = "--all-methods" in sys.argv  # the tables hold the OSS rows unless asked for every method


def runs_from_args(argv):
    argv = [a for a in argv if a != "--all-methods"]
    if argv[0] == "--from-json":
        return [json.load(open(path)) for path in argv[1:]]
    skinpack, rest, isas = argv[0], [], ["avx512", "avx2", "scalar"]
    i = 1
    while i < len(argv):
        if argv[i] == "--isa":
            isas = argv[i + 1].split(",")
            i += 2
        else:
            rest.append(argv[i])
            i += 1
    runs = []
    for isa in isas:
        out = subprocess.run([skinpack, "bench", "--json", "--isa", isa] + rest, check=True, capture_output=True,
                             text=True).stdout
        runs.append(json.loads(out))
    return runs


def mark(value, bar):
    return f"{value:.3f} {'✓' if value >= bar else '✗'}"


def print_run(run):
    memcpy = run["memcpy_vertices_per_s"]
    scalar = run["isa"] == "scalar"
    print(f"### Vector path: {run['isa']} (CPU has {run['cpu_isa']})\n")
    print(f"{run['vertices']} vertices, single thread, {run['repeats']} repetitions. "
          f"memcpy of the weights ({run['memcpy_bytes_per_vertex']} B/vertex): {memcpy / 1e6:.0f} M vertices/s; "
          f"tuple table build: {run['lut_build_vertices_per_s'] / 1e6:.1f} M vertices/s "
          f"({run['lut_build_ratio']:.3f}x memcpy, {run['lut_size']} tuples).\n")
    bars = (SCALAR_ENCODE, SCALAR_DECODE) if scalar else (TARGET, TARGET)
    print(f"{'' if ALL_METHODS else 'OSS rows only (the other methods are in the JSON); '}best-of ratios of OSS marked against "
          f"{'the scalar bars 1/7.8 and 1/44' if scalar else 'the 0.5x target'}; median ratios beside them.\n")
    print("| method | K | budget | bits | path | encode M/s | encode / memcpy best | median "
          "| decode M/s | decode / memcpy best | median |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for c in run["codecs"]:
        oss = c["method"] == "oss"
        if not oss and not ALL_METHODS:
            continue
        best = [c.get("encode_best_ratio", c["encode_ratio"]), c.get("decode_best_ratio", c["decode_ratio"])]
        enc = mark(best[0], bars[0]) if oss else f"{best[0]:.3f}"
        dec = mark(best[1], bars[1]) if oss else f"{best[1]:.3f}"
        print(f"| {c['method']} | {c['influences']} | {c['budget']} | {c['bits']} | "
              f"{path_name(c)} | {c['encode_vertices_per_s'] / 1e6:.1f} | {enc} | "
              f"{c['encode_ratio']:.3f} | {c['decode_vertices_per_s'] / 1e6:.1f} | {dec} | {c['decode_ratio']:.3f} |")
    print()


def path_name(codec):
    """'vector', 'scalar', or which direction has the vector path."""
    encode, decode = codec["encode_vector"], codec["decode_vector"]
    if encode == decode:
        return "vector" if encode else "scalar"
    return "vector decode" if decode else "vector encode"


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    runs = runs_from_args(sys.argv[1:])
    print(f"Machine: {platform.processor() or platform.machine()}.\n")
    for run in runs:
        print_run(run)


if __name__ == "__main__":
    main()
