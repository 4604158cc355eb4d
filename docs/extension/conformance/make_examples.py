"""Writes the example files of the specification (docs/extension/conformance/examples/): one tiny
.glb per mode, compressed by the skinpack CLI from tests/fuzz/corpus/file_reader/tiny.glb, and
next to each a .json with the joints and float32 weights (hex bit patterns) of every packed
primitive as `skinpack decompress` decodes them. Run by hand when the format changes; the tests
check the committed files (tests/unit/spec_reference.py and tests/unit/check_examples.py).

    python3 docs/extension/conformance/make_examples.py build/native/cli/skinpack
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, '..', '..', '..')
sys.path.insert(0, os.path.join(ROOT, 'tests', 'unit'))
from check_examples import decoded_influences  # noqa: E402

SOURCE = os.path.join(ROOT, 'tests', 'fuzz', 'corpus', 'file_reader', 'tiny.glb')
EXAMPLES = [
    ('fallback_oss', ['--method', 'oss', '--fallback']),
    ('compact_any', ['--method', 'any', '--compact', '--vertex-bits', '12']),
    ('meshlets_fixed', ['--method', 'fixed', '--fallback', '--meshlets', '--weight-bits', '24']),
]


def main():
    skinpack = sys.argv[1]
    out_dir = os.path.join(HERE, 'examples')
    os.makedirs(out_dir, exist_ok=True)
    for name, options in EXAMPLES:
        glb = os.path.join(out_dir, name + '.glb')
        subprocess.run([skinpack, 'compress', SOURCE, '-o', glb] + options, check=True, stdout=subprocess.DEVNULL)
        with tempfile.TemporaryDirectory() as tmp:
            primitives = decoded_influences(skinpack, glb, os.path.join(tmp, 'decoded.glb'))
        with open(os.path.join(out_dir, name + '.json'), 'w') as f:
            json.dump({'source': 'tests/fuzz/corpus/file_reader/tiny.glb', 'options': options,
                       'primitives': primitives}, f, indent=1)
            f.write('\n')
        print(name, [len(p['joints']) for p in primitives], 'vertices')


if __name__ == '__main__':
    main()
