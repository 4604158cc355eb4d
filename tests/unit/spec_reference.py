"""Runs the normative Python of docs/extension/README.md as written: every ```python block is
executed in one namespace, then checked against the conformance vectors (integers, float32 bit
patterns, rejections with their reason) and against the spec's integer-width table (the largest
weightBits each OSS K decodes with 32- and 64-bit integers, recomputed from the reference
formulas). With example .glb files given, also decodes them with the spec's decode_vertex and
compares with their expected .json.
usage: spec_reference.py README.md weights.jsonl [examples_dir]"""
import json
import os
import re
import struct
import sys


def load_reference(readme):
    text = open(readme, encoding='utf-8').read()
    blocks = re.findall(r'```python\n(.*?)```', text, re.S)
    if len(blocks) < 5:
        sys.exit('FAIL: %s has %d python blocks' % (readme, len(blocks)))
    namespace = {}
    exec(compile('\n'.join(blocks), readme, 'exec'), namespace)
    return text, namespace


def f32_hex(x):
    return '%08x' % struct.unpack('<I', struct.pack('<f', x))[0]


def check_vectors(ns, path):
    failures = count = 0
    for number, line in enumerate(open(path), 1):
        v = json.loads(line)
        count += 1
        c = ns['make_codec'](v['method'], v['influences'], int(v['n']), [int(q) for q in v['axisSamples']])
        if (c['weightBits'], c['count'] - 1, c['scale']) != (v['weightBits'], int(v['maxCode']), int(v['scale'])):
            failures += 1
            print('line %d: codec %s' % (number, c))
            continue
        try:
            grid, weights = ns['decode_weights'](c, int(v['code']))
            if not v['valid']:
                failures += 1
                print('line %d: invalid code accepted' % number)
            elif [str(g) for g in grid] != v['grid'] or [f32_hex(w) for w in weights] != v['weights']:
                failures += 1
                print('line %d: %s %s, vector %s %s' % (number, grid, weights, v['grid'], v['weights']))
        except ns['Invalid'] as e:
            if v['valid'] or str(e) != v['reason']:
                failures += 1
                print('line %d: rejected (%s)' % (number, e))
    print('%d vectors, %d failures' % (count, failures))
    return failures


def oss_widths(ns, k, bits):
    """Largest weightBits of OSS K whose decode keeps every intermediate below 2^bits."""
    largest, layer_base, row_base, triangle_count = ns['largest'], ns['layer_base'], ns['row_base'], ns['triangle_count']
    best = 0
    for w in range(2, 65):
        count = lambda n: [n, triangle_count(n), layer_base(n, (n + 1) // 2)][k - 2]
        n = largest(2, 2 ** 63, lambda n: count(n) <= 2 ** w)
        peak = 2 * (n - 1)
        if k >= 3:
            rows = (2 * n + 1) // 3
            j = min(rows - 1, (4 * n + 2) // 6)
            peak = max(peak, n * n + n + 1, max(x * (4 * n + 2 - 3 * x) + 1 for x in {max(0, j - 1), j, min(rows - 1, j + 1)}))
        if k == 4:
            top = (n + 1) // 2
            for layer in {top, top - 1} | {max(0, min(top, (n + 3) // 4 + d)) for d in range(-2, 3)}:
                a = 3 * n * layer * (n - 2 * layer + 3)
                peak = max(peak, a + 4 * layer ** 3 + 6 * layer + 2)
        if peak < 2 ** bits:
            best = max(best, (count(n) - 1).bit_length())
    return best


def check_width_table(ns, text):
    failures = 0
    for k in (2, 3, 4):
        row = re.search(r'^\| oss, K = %d \| (\d+) .*?\| (\d+)' % k, text, re.M)
        want = (oss_widths(ns, k, 32), oss_widths(ns, k, 64))
        if not row or (int(row.group(1)), int(row.group(2))) != want:
            failures += 1
            print('integer-width table, oss K = %d: spec says %s, the formulas give %s' % (k, row and row.groups(), want))
    print('integer-width table checked, %d failures' % failures)
    return failures


def read_glb(path):
    data = open(path, 'rb').read()
    magic, _, length = struct.unpack_from('<III', data, 0)
    assert magic == 0x46546C67 and length == len(data)
    json_length, _ = struct.unpack_from('<II', data, 12)
    doc = json.loads(data[20:20 + json_length])
    offset = 20 + json_length
    bin_length, _ = struct.unpack_from('<II', data, offset)
    return doc, data[offset + 8:offset + 8 + bin_length]


def read_accessor(doc, binary, index):
    acc = doc['accessors'][index]
    view = doc['bufferViews'][acc['bufferView']]
    width = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4}[acc['type']]
    code = {5121: 'B', 5123: 'H', 5125: 'I', 5126: 'f'}[acc['componentType']]
    start = view.get('byteOffset', 0) + acc.get('byteOffset', 0)
    values = struct.unpack_from('<%d%s' % (acc['count'] * width, code), binary, start)
    return [values[i:i + width] for i in range(0, len(values), width)], width


def check_examples(ns, folder):
    failures = checked = 0
    for name in sorted(os.listdir(folder)):
        if not name.endswith('.glb'):
            continue
        doc, binary = read_glb(os.path.join(folder, name))
        expected = json.load(open(os.path.join(folder, name[:-4] + '.json')))
        for entry in expected['primitives']:
            ext = doc['meshes'][entry['mesh']]['primitives'][entry['primitive']]['extensions']['SKINPACK_packed_skin']
            c = ns['make_codec'](ext['method'], ext['influences'], int(ext['n']),
                                 [int(q) for q in ext.get('axisSamples', [])])
            words, words_per_vertex = read_accessor(doc, binary, ext['vertices'])
            flat = [w for group in words for w in group]
            lut, _ = read_accessor(doc, binary, ext['tupleTable'])
            for v, (joints, weights) in enumerate(zip(entry['joints'], entry['weights'])):
                got_joints, got_weights = ns['decode_vertex'](c, flat, words_per_vertex, v, lut, ext['tupleBits'])
                checked += 1
                if got_joints != joints or [f32_hex(w) for w in got_weights] != weights:
                    failures += 1
                    print('%s mesh %d vertex %d: %s %s, expected %s %s' % (name, entry['mesh'], v, got_joints,
                                                                        got_weights, joints, weights))
    print('examples: %d vertices checked, %d failures' % (checked, failures))
    return failures if checked else 1


def main():
    text, ns = load_reference(sys.argv[1])
    failures = check_vectors(ns, sys.argv[2]) + check_width_table(ns, text)
    if len(sys.argv) > 3:
        failures += check_examples(ns, sys.argv[3])
    print('FAIL' if failures else 'PASS')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
