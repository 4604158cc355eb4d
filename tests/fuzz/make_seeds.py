"""Regenerates the committed seed corpora of the fuzzers (tests/fuzz/corpus/*).

    python3 tests/fuzz/make_seeds.py SKINPACK_BIN

file_reader seeds: a minimal skinned triangle strip as .glb and .gltf, standard and packed with
every codec (packed ones written by SKINPACK_BIN compress --compact / --fallback, one with
--meshlets).
extension_decoder seeds: the packed arrays of those files in fuzz_extension_decoder.c's layout.
"""
import base64
import json
import os
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "cli"))
import gltf_read  # noqa: E402

METHODS = {"fixed": 0, "cube": 1, "pot": 2, "any": 3, "oss": 4}


def tiny_skin():
    """Six vertices, three joints, 1..3 influences: the smallest file that exercises the LUT."""
    positions = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0, 2, 0), (1, 2, 0)]
    joints = [(0, 0, 0, 0), (0, 1, 0, 0), (1, 0, 0, 0), (1, 2, 0, 0), (2, 1, 0, 0), (2, 0, 1, 0)]
    weights = [(1, 0, 0, 0), (0.75, 0.25, 0, 0), (0.5, 0.5, 0, 0), (0.6, 0.4, 0, 0), (0.9, 0.1, 0, 0),
               (0.5, 0.3, 0.2, 0)]
    indices = [0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5]
    ibm = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] * 3
    blob = b"".join(struct.pack("<3f", *p) for p in positions)
    blob += b"".join(struct.pack("<4B", *j) for j in joints)
    blob += b"".join(struct.pack("<4f", *w) for w in weights)
    blob += struct.pack("<12H", *indices)
    blob += struct.pack("<48f", *ibm)
    views = [(0, 72, 34962), (72, 24, 34962), (96, 96, 34962), (192, 24, 34963), (216, 192, None)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0, "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"children": [2]}, {"children": [3], "translation": [0, 1, 0]},
                  {"translation": [0, 1, 0]}],
        "skins": [{"joints": [1, 2, 3], "inverseBindMatrices": 4}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}, "indices": 3}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3", "min": [0, 0, 0], "max": [1, 2, 0]},
            {"bufferView": 1, "componentType": 5121, "count": 6, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": 6, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": 12, "type": "SCALAR"},
            {"bufferView": 4, "componentType": 5126, "count": 3, "type": "MAT4"},
        ],
        "bufferViews": [dict({"buffer": 0, "byteOffset": o, "byteLength": n}, **({"target": t} if t else {}))
                        for o, n, t in views],
        "buffers": [{"byteLength": len(blob)}],
    }
    return doc, blob


def decoder_seed(path):
    doc = gltf_read.Gltf(path)
    for _, _, prim in doc.primitives():
        e = prim.get("extensions", {}).get(gltf_read.EXTENSION)
        if not e:
            continue
        words = doc.accessor(e["vertices"])
        lut = doc.accessor(e["tupleTable"])
        axes = (e.get("axisSamples", []) + [0, 0, 0])[:3]
        header = struct.pack("<BBBBHHQ3QIB", METHODS[e["method"]], e["influences"], e["weightBits"], e["tupleBits"],
                             e["jointCount"], e["jointCount"], e["n"], *axes, len(lut), len(words[0]))
        return header + b"".join(struct.pack("<%dH" % len(t), *t) for t in lut) + \
            b"".join(struct.pack("<%dI" % len(w), *w) for w in words)
    raise SystemExit("%s has no packed primitive" % path)


def main():
    skinpack = sys.argv[1]
    reader = os.path.join(HERE, "corpus", "file_reader")
    decoder = os.path.join(HERE, "corpus", "extension_decoder")
    os.makedirs(reader, exist_ok=True)
    os.makedirs(decoder, exist_ok=True)
    doc, blob = tiny_skin()
    gltf_read.write_glb(doc, blob, os.path.join(reader, "tiny.glb"))
    text = dict(doc, buffers=[{"byteLength": len(blob),
                               "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}])
    with open(os.path.join(reader, "tiny.gltf"), "w") as f:
        json.dump(text, f)
    with tempfile.TemporaryDirectory() as tmp:
        for method, option in [("oss", "--vertex-bits=32"), ("any", "--weight-bits=12"), ("pot", "--weight-bits=10"),
                               ("cube", "--weight-bits=8"), ("fixed", "--weight-bits=12")]:
            for mode in ("compact", "fallback"):
                out = os.path.join(reader, "tiny_%s_%s.glb" % (method, mode))
                subprocess.run([skinpack, "compress", os.path.join(reader, "tiny.glb"), "-o", out, "--method", method,
                                option.split("=")[0], option.split("=")[1], "--" + mode], check=True,
                               capture_output=True)
            with open(os.path.join(decoder, "tiny_%s.bin" % method), "wb") as f:
                f.write(decoder_seed(os.path.join(reader, "tiny_%s_compact.glb" % method)))
        out = os.path.join(reader, "tiny_oss_meshlets.glb")
        subprocess.run([skinpack, "compress", os.path.join(reader, "tiny.glb"), "-o", out, "--compact", "--meshlets"],
                       check=True, capture_output=True)
        out = os.path.join(reader, "tiny_oss_compact.gltf")
        subprocess.run([skinpack, "compress", os.path.join(reader, "tiny.glb"), "-o", out, "--compact"], check=True,
                       capture_output=True)
    print("seeds written to", reader, "and", decoder)


main()
