"""Skinned files full of what a regenerating writer loses (issue 10, item 1).

    python3 make_rich_gltf.py FOX.glb OUT_DIR

From Fox.glb it writes, under OUT_DIR:
  rich/rich.gltf      external buffer in a subfolder (data/fox.bin), an external image
                      (textures/fox.png, with mimeType), a data: uri image, an unknown
                      extension, custom properties outside extras, asset.minVersion, an empty
                      node, scene and texture, a camera without zfar, a KHR_animation_pointer
                      channel without target.node, extras everywhere
  rich/rich_known.glb the same as one GLB without the unknown extension and with the image in
                      the BIN chunk (so compact mode may cut bytes out of the BIN chunk)
"""
import base64
import json
import os
import struct
import sys

TINY_PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg==")


def read_glb(path):
    with open(path, "rb") as f:
        data = f.read()
    length = struct.unpack_from("<I", data, 12)[0]
    document = json.loads(data[20:20 + length])
    offset = 20 + length
    return document, bytearray(data[offset + 8:offset + 8 + struct.unpack_from("<I", data, offset)[0]])


def enrich(doc, unknown_extension):
    doc["asset"]["minVersion"] = "2.0"
    doc["asset"]["extras"] = {"note": "kept"}
    doc["customRootProperty"] = {"a": [1, 2.5, "x"]}
    doc["nodes"].append({})  # an empty node
    doc["nodes"][0]["customNodeProperty"] = 7
    doc["nodes"][0]["extras"] = {"flag": True}
    doc["scenes"].append({})  # an empty scene
    doc["textures"].append({})  # an empty texture
    doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}]  # no zfar
    doc["nodes"].append({"name": "camera", "camera": 0})
    doc["meshes"][0]["extras"] = {"mesh": "extras"}
    doc["meshes"][0]["primitives"][0]["extras"] = {"primitive": "extras"}
    doc["skins"][0]["extras"] = {"skin": 1}
    doc["materials"][0]["customMaterialProperty"] = "kept"
    # A KHR_animation_pointer channel: no target.node, a pointer instead.
    sampler = dict(doc["animations"][0]["samplers"][0])
    doc["animations"].append({"name": "pointer", "samplers": [sampler], "channels": [
        {"sampler": 0, "target": {"path": "pointer",
                                  "extensions": {"KHR_animation_pointer": {"pointer": "/nodes/8/rotation"}}}}]})
    used = ["KHR_animation_pointer"]
    if unknown_extension:
        doc["materials"][0]["extensions"] = {"EXT_skinpack_test_unknown": {"anything": [1, {"b": None}]}}
        used.append("EXT_skinpack_test_unknown")
    doc["extensionsUsed"] = used
    doc["images"].append({"uri": "data:image/png;base64," + base64.b64encode(TINY_PNG).decode(), "name": "inline"})
    doc["textures"].append({"source": len(doc["images"]) - 1, "sampler": 0})


def write_gltf(doc, binary, out_dir):
    """rich.gltf: the Fox image moves to textures/fox.png, the buffer to data/fox.bin."""
    doc = json.loads(json.dumps(doc))
    image = doc["images"][0]
    view = doc["bufferViews"][image["bufferView"]]
    png = bytes(binary[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]])
    os.makedirs(os.path.join(out_dir, "textures"), exist_ok=True)
    os.makedirs(os.path.join(out_dir, "data"), exist_ok=True)
    with open(os.path.join(out_dir, "textures", "fox.png"), "wb") as f:
        f.write(png)
    doc["images"][0] = {"uri": "textures/fox.png", "mimeType": "image/png", "name": "fox"}
    # The image's view is unused now; keep it (its bytes stay in the buffer) as real files do.
    with open(os.path.join(out_dir, "data", "fox.bin"), "wb") as f:
        f.write(binary)
    doc["buffers"] = [{"uri": "data/fox.bin", "byteLength": len(binary), "extras": {"buffer": "extras"}}]
    with open(os.path.join(out_dir, "rich.gltf"), "w") as f:
        json.dump(doc, f, indent=2)


def write_glb(doc, binary, path):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    doc_length = 12 + 8 + len(text) + 8 + len(binary)
    with open(path, "wb") as f:
        f.write(struct.pack("<III", 0x46546C67, 2, doc_length))
        f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)


def main():
    fox, out = sys.argv[1], sys.argv[2]
    doc, binary = read_glb(fox)
    out_dir = os.path.join(out, "rich")
    os.makedirs(out_dir, exist_ok=True)
    rich = json.loads(json.dumps(doc))
    enrich(rich, unknown_extension=True)
    write_gltf(rich, binary, out_dir)
    known = json.loads(json.dumps(doc))
    enrich(known, unknown_extension=False)
    write_glb(known, binary, os.path.join(out_dir, "rich_known.glb"))
    print("wrote", out_dir)


if __name__ == "__main__":
    main()
