"""The specification's example files against the CLI: `skinpack decompress` of every
docs/extension/conformance/examples/*.glb must give the joints and float32 weights its .json
lists (per packed primitive, K slots in weight order), and `skinpack info` must accept it.
usage: check_examples.py SKINPACK_BIN EXAMPLES_DIR"""
import json
import os
import struct
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'cli'))
import gltf_read  # noqa: E402


def f32_hex(x):
    return '%08x' % struct.unpack('<I', struct.pack('<f', x))[0]


def packed_primitives(path):
    for m, p, prim in gltf_read.Gltf(path).primitives():
        ext = prim.get('extensions', {}).get('SKINPACK_packed_skin')
        if ext:
            yield m, p, ext


def decoded_influences(skinpack, packed, decoded_path):
    """Decompresses packed with the CLI; returns, per packed primitive, K joints and weights a vertex."""
    subprocess.run([skinpack, 'decompress', packed, '-o', decoded_path], check=True, stdout=subprocess.DEVNULL)
    doc = gltf_read.Gltf(decoded_path)
    result = []
    for m, p, ext in packed_primitives(packed):
        attributes = doc.json['meshes'][m]['primitives'][p]['attributes']
        joints = doc.accessor(attributes['JOINTS_0'])
        weights = doc.accessor(attributes['WEIGHTS_0'])
        k = ext['influences']
        result.append({'mesh': m, 'primitive': p,
                       'joints': [[int(j) for j in row[:k]] for row in joints],
                       'weights': [[f32_hex(w) for w in row[:k]] for row in weights]})
    return result


def main():
    skinpack, folder = sys.argv[1], sys.argv[2]
    failures = checked = 0
    for name in sorted(os.listdir(folder)):
        if not name.endswith('.glb'):
            continue
        path = os.path.join(folder, name)
        expected = json.load(open(path[:-4] + '.json'))['primitives']
        info = subprocess.run([skinpack, 'info', path], capture_output=True, text=True)
        if info.returncode != 0:
            failures += 1
            print('%s: info refuses it: %s' % (name, info.stderr.strip()))
        with tempfile.TemporaryDirectory() as tmp:
            got = decoded_influences(skinpack, path, os.path.join(tmp, 'decoded.glb'))
        for want, have in zip(expected, got):
            checked += len(want['joints'])
            if want != have:
                failures += 1
                print('%s mesh %d primitive %d: decompress gives %s, expected %s' % (name, want['mesh'],
                      want['primitive'], have, want))
        if len(expected) != len(got) or not expected:
            failures += 1
            print('%s: %d packed primitives, %d expected' % (name, len(got), len(expected)))
    print('%d example vertices checked, %d failures' % (checked, failures))
    print('FAIL' if failures or not checked else 'PASS')
    return 1 if failures or not checked else 0


if __name__ == '__main__':
    sys.exit(main())
