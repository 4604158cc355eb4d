#!/usr/bin/env python3
"""A/B of two skinpack binaries' `bench --json`, run alternately in one session, so that the
shared machine's drift (its memcpy baseline moves by 2x between runs) hits both alike.

usage: core_bench_ab.py OLD_SKINPACK NEW_SKINPACK avx2|avx512|scalar ROUNDS
Prints a Markdown table: per OSS row, the median over rounds of each binary's best-of ratio to
memcpy, the ratio of their median rates (the robust figure) and the range of each binary's decode
rate over the rounds (each round a new process: what the process's own layout changes shows
there). Nothing is asserted."""
import json, subprocess, sys, statistics
old, new, isa, rounds = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])

res = {"old": [], "new": []}
for r in range(rounds):
    for name, exe in (("old", old), ("new", new)) if r % 2 == 0 else (("new", new), ("old", old)):
        out = subprocess.run([exe, "bench", "--json", "--isa", isa, "--repeats", "7"], check=True, capture_output=True, text=True).stdout
        res[name].append(json.loads(out))
rows = {}
for name in res:
    for run in res[name]:
        for c in run["codecs"]:
            if c["method"] != "oss": continue
            key = (c["influences"], c["bits"])
            rows.setdefault(key, {"old": [], "new": []})[name].append(c)
mem = {n: [r["memcpy_vertices_per_s"] / 1e6 for r in res[n]] for n in res}
print(f"isa {isa}, {rounds} rounds; memcpy M/s old {min(mem['old']):.0f}-{max(mem['old']):.0f}, new {min(mem['new']):.0f}-{max(mem['new']):.0f}")
print("| K | bits | encode best ratio old → new | encode rate new/old | decode best ratio old → new | decode rate new/old "
      "| decode M/s over the rounds, old → new |")
print("|---|---|---|---|---|---|---|")
for key in sorted(rows):
    o, n = rows[key]["old"], rows[key]["new"]
    f = lambda l, k: statistics.median(c[k] for c in l)
    span = lambda l: f"{min(c['decode_vertices_per_s'] for c in l) / 1e6:.0f}–{max(c['decode_vertices_per_s'] for c in l) / 1e6:.0f}"
    print(f"| {key[0]} | {key[1]} | {f(o,'encode_best_ratio'):.3f} → {f(n,'encode_best_ratio'):.3f} | {f(n,'encode_vertices_per_s')/f(o,'encode_vertices_per_s'):.2f}× "
          f"| {f(o,'decode_best_ratio'):.3f} → {f(n,'decode_best_ratio'):.3f} | {f(n,'decode_vertices_per_s')/f(o,'decode_vertices_per_s'):.2f}× "
          f"| {span(o)} → {span(n)} |")
