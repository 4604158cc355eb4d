#!/usr/bin/env python3
"""Fails when the library's source files call each other in a circle.

usage: check_file_cycles.py OBJECT... (the objects of skinpack_objects; ';'-lists are split)
Each object's undefined symbols are matched to the object defining them (nm); any cycle in
that graph is reported with the files on it.
"""
import os
import subprocess
import sys

KNOWN = set()  # cycles tolerated for now: none


def symbols(path):
    defined, undefined = set(), set()
    for line in subprocess.run(["nm", path], check=True, capture_output=True, text=True).stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[1] in "TDBRC":
            defined.add(parts[2])
        elif len(parts) == 2 and parts[0] == "U":
            undefined.add(parts[1])
    return defined, undefined


def cycles(graph):
    """Strongly connected components of more than one file (Tarjan)."""
    index, low, stack, on_stack, found, counter = {}, {}, [], set(), [], [0]

    def visit(node):
        index[node] = low[node] = counter[0]
        counter[0] += 1
        stack.append(node)
        on_stack.add(node)
        for other in graph[node]:
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in on_stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            component = set()
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.add(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(component)

    for node in graph:
        if node not in index:
            visit(node)
    return found


def main():
    objects = [p for arg in sys.argv[1:] for p in arg.split(";") if p]
    if not objects:
        sys.exit(__doc__)
    name = {p: os.path.basename(p).replace(".o", "").replace(".obj", "") for p in objects}
    table = {p: symbols(p) for p in objects}
    owner = {s: name[p] for p, (defined, _) in table.items() for s in defined}
    graph = {name[p]: sorted({owner[s] for s in undefined if s in owner and owner[s] != name[p]})
             for p, (_, undefined) in table.items()}
    bad = [c for c in cycles(graph) if frozenset(c) not in KNOWN]
    for c in bad:
        print("Error: source files call each other in a circle: " + " <-> ".join(sorted(c)))
    print(f"{len(graph)} library objects, {sum(len(v) for v in graph.values())} file dependencies, "
          f"{len(bad)} cycle(s) outside the known list")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
