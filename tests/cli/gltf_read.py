"""A tiny, independent glTF reader for the CLI tests (plain Python, no numpy).

It is deliberately separate from the CLI's tinygltf code so that a bug there cannot hide itself:
it reads .glb and .gltf (data: or relative uris), any accessor with stride and normalisation,
and returns per-vertex influence lists.
"""
import base64
import json
import os
import struct

COMPONENT = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
NORMALIZE = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}
TYPE = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
EXTENSION = "SKINPACK_packed_skin"


class Gltf:
    def __init__(self, path):
        self.path = path
        with open(path, "rb") as f:
            data = f.read()
        self.bin = None
        if data[:4] == b"glTF":
            json_length = struct.unpack_from("<I", data, 12)[0]
            self.json = json.loads(data[20:20 + json_length])
            offset = 20 + json_length
            if offset + 8 <= len(data):
                bin_length = struct.unpack_from("<I", data, offset)[0]
                self.bin = data[offset + 8:offset + 8 + bin_length]
        else:
            self.json = json.loads(data)
        self.buffers = []
        for index, buffer in enumerate(self.json.get("buffers", [])):
            uri = buffer.get("uri")
            if uri is None:  # the GLB chunk; other buffers without uri have no data (fallback buffers)
                self.buffers.append(self.bin if index == 0 else None)
            elif uri.startswith("data:"):
                self.buffers.append(base64.b64decode(uri.split(",", 1)[1]))
            else:
                with open(os.path.join(os.path.dirname(path), uri), "rb") as f:
                    self.buffers.append(f.read())

    def accessor(self, index, normalized_as_float=True):
        """Elements of an accessor as lists of numbers (None data -> zeros)."""
        a = self.json["accessors"][index]
        fmt, size = COMPONENT[a["componentType"]]
        n = TYPE[a["type"]]
        if "bufferView" not in a:
            return [[0] * n for _ in range(a["count"])]
        view = self.json["bufferViews"][a["bufferView"]]
        data = self.buffers[view["buffer"]]
        stride = view.get("byteStride", size * n)
        base = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        scale = NORMALIZE.get(a["componentType"]) if a.get("normalized") and normalized_as_float else None
        out = []
        for i in range(a["count"]):
            values = list(struct.unpack_from("<%d%s" % (n, fmt), data, base + i * stride))
            if scale:
                values = [max(v / scale, -1.0) for v in values]
            out.append(values)
        return out

    def primitives(self):
        for m, mesh in enumerate(self.json.get("meshes", [])):
            for p, prim in enumerate(mesh["primitives"]):
                yield m, p, prim

    def influences(self, prim):
        """Per vertex, a dict joint -> summed weight over JOINTS_n/WEIGHTS_n (zero weights dropped)."""
        attributes = prim["attributes"]
        sets = []
        s = 0
        while "JOINTS_%d" % s in attributes:
            sets.append((self.accessor(attributes["JOINTS_%d" % s]), self.accessor(attributes["WEIGHTS_%d" % s])))
            s += 1
        if not sets:
            return None
        result = []
        for v in range(len(sets[0][0])):
            d = {}
            for joints, weights in sets:
                for j, w in zip(joints[v], weights[v]):
                    if w > 0:
                        d[int(j)] = d.get(int(j), 0.0) + w
            result.append(d)
        return result


def prepare(influence, k):
    """What docs/format.md section 1 says the compressor keeps: normalise, sort by descending
    weight (ties: lower joint), keep the k largest, renormalise."""
    items = sorted(influence.items(), key=lambda jw: (-jw[1], jw[0]))[:k]
    total = sum(w for _, w in items)
    return {j: w / total for j, w in items}


def write_glb(document, binary, path):
    """Writes a GLB from a JSON document and the BIN chunk bytes (for making broken files)."""
    text = json.dumps(document).encode()
    text += b" " * (-len(text) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<I", len(text)) + b"JSON" + text
    if binary:
        chunks += struct.pack("<I", len(binary)) + b"BIN\0" + binary
    with open(path, "wb") as f:
        f.write(b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks)
