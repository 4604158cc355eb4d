"""Writes a small valid skinned .glb whose vertices have 1 to 8 influences (JOINTS_0/WEIGHTS_0
and JOINTS_1/WEIGHTS_1), to test the stride-8 path and pruning to K = 4, with two primitives
that share all their accessors. With MAX (1..8) vertices have 1 to MAX influences: MAX 1
makes a rigid, single-influence mesh (K = 1).

    python3 make_eight_influences.py OUT.glb [MAX]
"""
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import gltf_read  # noqa: E402

JOINTS = 8


def vertex_influences(v, most):
    """Deterministic, distinct joints with strictly decreasing weights; 1..most influences."""
    count = 1 + v % most
    joints = [(v * 3 + i * 5) % JOINTS for i in range(count)]
    joints = list(dict.fromkeys(joints))  # distinct, order kept
    raw = [1.0 / (i + 1.5) ** 1.3 for i in range(len(joints))]
    total = sum(raw)
    weights = [w / total for w in raw]
    weights[0] += 1.0 - sum(weights)  # exact sum in double; float rounding stays tiny
    return joints, weights


def main():
    out = sys.argv[1]
    most = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    columns, rows = 4, 6
    positions, joints0, joints1, weights0, weights1 = [], [], [], [], []
    for y in range(rows):
        for x in range(columns):
            v = y * columns + x
            positions.append((float(x), float(y), 0.0))
            j, w = vertex_influences(v, most)
            j += [0] * (8 - len(j))
            w += [0.0] * (8 - len(w))
            joints0.append(j[:4])
            joints1.append(j[4:])
            weights0.append(w[:4])
            weights1.append(w[4:])
    indices = []
    for y in range(rows - 1):
        for x in range(columns - 1):
            a = y * columns + x
            indices += [a, a + 1, a + columns, a + columns, a + 1, a + columns + 1]
    n = len(positions)
    parts = [b"".join(struct.pack("<3f", *p) for p in positions),
             b"".join(struct.pack("<4B", *j) for j in joints0),
             b"".join(struct.pack("<4f", *w) for w in weights0),
             b"".join(struct.pack("<4B", *j) for j in joints1),
             b"".join(struct.pack("<4f", *w) for w in weights1),
             struct.pack("<%dH" % len(indices), *indices) + b"\0" * (len(indices) % 2 * 2),
             struct.pack("<%df" % (16 * JOINTS), *([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1] * JOINTS))]
    views, blob = [], b""
    for part in parts:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(part)})
        blob += part
    for i in range(5):
        views[i]["target"] = 34962
    views[5]["target"] = 34963
    views[5]["byteLength"] = 2 * len(indices)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"children": list(range(2, 1 + JOINTS))}] +
                 [{"translation": [0.5 * i, 0, 0]} for i in range(1, JOINTS)],
        "skins": [{"joints": list(range(1, 1 + JOINTS)), "inverseBindMatrices": 6}],
        # Two primitives share every accessor (as a mesh with two materials over the same
        # vertices would): skinpack must compress them once and share the packed accessors.
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2, "JOINTS_1": 3,
                                                   "WEIGHTS_1": 4}, "indices": 5}] * 2}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": [0, 0, 0],
             "max": [columns - 1, rows - 1, 0]},
            {"bufferView": 1, "componentType": 5121, "count": n, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5121, "count": n, "type": "VEC4"},
            {"bufferView": 4, "componentType": 5126, "count": n, "type": "VEC4"},
            {"bufferView": 5, "componentType": 5123, "count": len(indices), "type": "SCALAR"},
            {"bufferView": 6, "componentType": 5126, "count": JOINTS, "type": "MAT4"},
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob)}],
    }
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    gltf_read.write_glb(doc, blob, out)


main()
