"""glTF import user extension: decodes SKINPACK_packed_skin into JOINTS_0/WEIGHTS_0.

gather_import_mesh_before_hook runs before the importer counts a primitive's JOINTS_n sets,
so the decoded joints and weights are added there as ordinary accessors (a new buffer holding
their bytes) and the importer builds the vertex groups as for any skinned file. The decoded
weights replace JOINTS_n/WEIGHTS_n of fallback files too: the mesh opens with exactly what
a Skinpack-aware runtime would use. Decoding (and all its validation) is the library's.
"""

import numpy as np

from ...io import extension as ext
from ...io import native
from ..com import gltf2_skinpack_io as gltf_api


def _decode_accessor(gltf, index):
    from io_scene_gltf2.io.imp.gltf2_io_binary import BinaryData
    return np.asarray(BinaryData.decode_accessor(gltf, index))


def _append_accessor(gltf, data, component_type, width):
    """Adds a buffer + bufferView + accessor holding data; returns the accessor index."""
    gltf2_io = gltf_api.gltf_io()
    payload = np.ascontiguousarray(data).tobytes()
    buffers = gltf.data.buffers
    buffer_index = len(buffers)
    buffers.append(gltf2_io.Buffer(byte_length=len(payload), extensions=None, extras=None, name=None, uri=None))
    gltf.buffers[buffer_index] = payload
    gltf.data.buffer_views.append(gltf2_io.BufferView(buffer=buffer_index, byte_length=len(payload), byte_offset=0,
                                                      byte_stride=None, extensions=None, extras=None, name=None,
                                                      target=None))
    gltf.data.accessors.append(gltf2_io.Accessor(buffer_view=len(gltf.data.buffer_views) - 1, byte_offset=0,
                                                 component_type=component_type, count=int(np.asarray(data).size // width),
                                                 extensions=None, extras=None, max=None, min=None, name=None,
                                                 normalized=None, sparse=None, type=ext.VECTOR_TYPES[width]))
    return len(gltf.data.accessors) - 1


def decode_primitive(gltf, primitive, extension):
    K = int(extension["influences"])
    words = _decode_accessor(gltf, extension["vertices"]).astype(np.uint32)
    vertex_count = words.shape[0]
    lut = _decode_accessor(gltf, extension["tupleTable"]).astype(np.uint16).ravel()
    joints, weights = native.decompress(extension["method"], K, int(extension["n"]),
                                        [int(q) for q in extension.get("axisSamples", [])], words.ravel(),
                                        vertex_count, int(extension["tupleBits"]), lut,
                                        int(extension["jointCount"]))
    # Pad to VEC4; an unused slot has weight 0 (joint 0 is always valid).
    padded_joints = np.zeros((vertex_count, 4), dtype="<u2")
    padded_weights = np.zeros((vertex_count, 4), dtype="<f4")
    padded_joints[:, :K] = joints
    padded_weights[:, :K] = weights
    for key in [k for k in primitive.attributes if k.startswith(("JOINTS_", "WEIGHTS_"))]:
        del primitive.attributes[key]
    primitive.attributes["JOINTS_0"] = _append_accessor(gltf, padded_joints, ext.COMPONENT_UNSIGNED_SHORT, 4)
    primitive.attributes["WEIGHTS_0"] = _append_accessor(gltf, padded_weights, ext.COMPONENT_FLOAT, 4)


class glTF2ImportUserExtension:
    def __init__(self):
        # A required extension must be declared, or the importer refuses the file.
        Extension = gltf_api.extension_class()
        self.extensions = [Extension(name=ext.EXTENSION_NAME, extension={}, required=True)]
        self.decoded = set()  # id() of primitives already decoded (a mesh can be built per skin)

    def gather_import_mesh_before_hook(self, pymesh, gltf):
        for primitive in pymesh.primitives:
            extension = (primitive.extensions or {}).get(ext.EXTENSION_NAME)
            if extension is None or id(primitive) in self.decoded:
                continue
            if native.load() is None:
                raise RuntimeError("Skinpack: %s" % native.load_error())
            decode_primitive(gltf, primitive, extension)
            self.decoded.add(id(primitive))
