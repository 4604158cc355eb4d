"""File-level mutation test of `skinpack decompress` (the issue-11 proof, end to end).

    python3 mutate_files.py SKINPACK_CLI NODE VALIDATE_MJS WORK_DIR ASSET.glb...

Each asset is compressed by the CLI (32-bit OSS fallback, Any compact at 12 bits, POT with
meshlets); then the .glb is mutated: bytes of the extension's bufferViews flipped, accessor
counts truncated, every extension property (and meshlet property) edited — including integers
of 2^32 and above, 2^53 + 2 as a float, strings, negatives —, accessor indices retargeted to
other accessors, and the primitive duplicated with contradicting properties on the same
accessors. Every `skinpack decompress` of a mutant must either exit 1 with an "Error: ..."
message and no output file, or write a file that the Khronos validator passes, without the
extension, whose decoded joints are all below the joint count of the skin and distinct wherever
weighted.

In ctest as cli_mutate_files (tests/cli/CMakeLists.txt: Fox and skinned_cylinder).
"""
import copy
import json
import os
import random
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'cli'))
import gltf_read  # noqa: E402

EXT = gltf_read.EXTENSION
CONFIGS = [('oss_fallback', ['--method', 'oss', '--fallback']),
           ('any_compact', ['--method', 'any', '--compact', '--vertex-bits', '12']),
           ('pot_meshlets', ['--method', 'pot', '--meshlets'])]
PROPERTIES = ['vertices', 'tupleTable', 'influences', 'jointCount', 'method', 'n', 'axisSamples', 'weightBits',
              'tupleBits', 'maxError']


def load(path):
    doc = gltf_read.Gltf(path)
    return doc.json, bytearray(doc.bin)


def packed(document):
    for m, mesh in enumerate(document['meshes']):
        for p, prim in enumerate(mesh['primitives']):
            if EXT in prim.get('extensions', {}):
                yield m, p, prim, prim['extensions'][EXT]


def view_range(document, accessor):
    a = document['accessors'][accessor]
    view = document['bufferViews'][a['bufferView']]
    start = view.get('byteOffset', 0) + a.get('byteOffset', 0)
    return start, view.get('byteOffset', 0) + view['byteLength']


def edited_values(value):
    if isinstance(value, int):
        return [value + 1, value - 1, 0, -1, 2 ** 32 + value, float(2 ** 53 + 2), str(value), 2 ** 64]
    if isinstance(value, float):
        return [-value, float('inf'), 'x', 2.0]
    if isinstance(value, list):
        return [[], value + [2], [2 ** 32 + q for q in value], [str(q) for q in value]]
    return [1, 'unknown', None]


def mutants(document, binary, rng):
    """(name, document, binary) triples."""
    for m, p, prim, ext in packed(document):
        regions = [('vertices', ext['vertices']), ('tupleTable', ext['tupleTable'])]
        for key, index in ext.get('meshlets', {}).items():
            if isinstance(index, int) and key not in ('maxVertices', 'maxTriangles', 'maxJoints'):
                regions.append(('meshlets.' + key, index))
        for name, accessor in regions:
            start, end = view_range(document, accessor)
            for i in range(6):
                b = bytearray(binary)
                at = rng.randrange(start, end)
                b[at] ^= 1 << rng.randrange(8)
                yield 'mesh %d %s byte %d flipped' % (m, name, at), document, b
            d = copy.deepcopy(document)
            d['accessors'][accessor]['count'] -= 1
            yield 'mesh %d %s count - 1' % (m, name), d, binary
        for key in PROPERTIES + ['meshlets.' + k for k in ext.get('meshlets', {})]:
            holder_path = key.split('.')
            current = ext.get(holder_path[0]) if len(holder_path) == 1 else ext['meshlets'].get(holder_path[1])
            for value in edited_values(current if current is not None else 0):
                d = copy.deepcopy(document)
                target = d['meshes'][m]['primitives'][p]['extensions'][EXT]
                if len(holder_path) == 2:
                    target = target['meshlets']
                target[holder_path[-1]] = value
                yield 'mesh %d %s = %r' % (m, key, value), d, binary
        for key, other in (('vertices', ext['tupleTable']), ('tupleTable', ext['vertices']),
                           ('vertices', prim['attributes']['POSITION']), ('tupleTable', prim['attributes'].get('JOINTS_0', 0))):
            d = copy.deepcopy(document)
            d['meshes'][m]['primitives'][p]['extensions'][EXT][key] = other
            yield 'mesh %d %s retargeted to accessor %d' % (m, key, other), d, binary
        d = copy.deepcopy(document)
        twin = copy.deepcopy(prim)
        twin['extensions'][EXT]['jointCount'] = max(1, ext['jointCount'] - 1)
        d['meshes'][m]['primitives'].append(twin)
        yield 'mesh %d second primitive on the same accessors with jointCount - 1' % m, d, binary


def skin_joints(document, mesh):
    counts = [len(document['skins'][n['skin']]['joints']) for n in document.get('nodes', [])
              if n.get('mesh') == mesh and 'skin' in n]
    return min(counts) if counts else None


def check_decoded(path):
    doc = gltf_read.Gltf(path)
    if EXT in doc.json.get('extensionsUsed', []):
        return 'the extension is still declared'
    for m, p, prim in doc.primitives():
        if 'JOINTS_0' not in prim['attributes']:
            continue
        limit = skin_joints(doc.json, m)
        joints, weights = doc.accessor(prim['attributes']['JOINTS_0']), doc.accessor(prim['attributes']['WEIGHTS_0'])
        for v, (js, ws) in enumerate(zip(joints, weights)):
            weighted = [int(j) for j, w in zip(js, ws) if w > 0]
            if (limit is not None and any(j >= limit for j in weighted)) or len(set(weighted)) != len(weighted):
                return 'mesh %d vertex %d decodes to joints %s weights %s (skin has %s joints)' % (m, v, js, ws, limit)
    return None


def main():
    skinpack, node, validator, work = sys.argv[1:5]
    os.makedirs(work, exist_ok=True)
    rng = random.Random(11)
    problems, written, refused, count = [], [], 0, 0
    for asset in sys.argv[5:]:
        stem = os.path.splitext(os.path.basename(asset))[0]
        for tag, options in CONFIGS:
            source = os.path.join(work, '%s_%s.glb' % (stem, tag))
            subprocess.run([skinpack, 'compress', asset, '-o', source] + options, check=True, stdout=subprocess.DEVNULL)
            document, binary = load(source)
            for name, d, b in mutants(document, binary, rng):
                count += 1
                mutant = os.path.join(work, 'mutant_%d.glb' % count)
                out = os.path.join(work, 'mutant_%d_decoded.glb' % count)
                gltf_read.write_glb(d, b, mutant)
                if os.path.exists(out):
                    os.remove(out)
                run = subprocess.run([skinpack, 'decompress', mutant, '-o', out], capture_output=True, text=True)
                what = '%s %s: %s' % (stem, tag, name)
                if run.returncode != 0:
                    refused += 1
                    if run.returncode != 1 or not run.stderr.startswith('Error: ') or os.path.exists(out):
                        problems.append('%s: exit %d, stderr %r' % (what, run.returncode, run.stderr.strip()[:200]))
                    os.remove(mutant)
                    continue
                problem = check_decoded(out)
                if problem:
                    problems.append('%s: decompress exits 0 but %s' % (what, problem))
                written.append((what, out))
                os.remove(mutant)
    for start in range(0, len(written), 50):
        batch = written[start:start + 50]
        run = subprocess.run([node, validator, '--json'] + [path for _, path in batch], capture_output=True, text=True)
        reports = {}
        for line in run.stdout.splitlines():
            if line.startswith('{'):
                r = json.loads(line)
                reports[r['file']] = r['issues']['numErrors']
        for what, path in batch:
            if reports.get(path, 1) != 0:
                problems.append('%s: decompress exits 0 but the Khronos validator reports %s errors' % (
                    what, reports.get(path, 'no report / ')))
    for line in problems[:40]:
        print(line)
    print('%d mutants: %d refused, %d written, %d problems' % (count, refused, len(written), len(problems)))
    print('PASS' if not problems and count else 'FAIL')
    return 0 if not problems and count else 1


if __name__ == '__main__':
    sys.exit(main())
