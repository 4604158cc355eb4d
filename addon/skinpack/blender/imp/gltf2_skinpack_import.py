"""glTF import user extension: decodes SKINPACK_packed_skin into JOINTS_0/WEIGHTS_0.

Before Blender creates anything (gather_import_gltf_before_hook), every packed primitive of the
file is validated and decoded by the library's sp_validate_packed, with what the file says:
the declared properties, the stored arrays, the primitive's vertex count, the smallest skin of
the nodes that use the mesh, the meshlet arrays. The decoded joints and weights then replace the
primitive's JOINTS_n/WEIGHTS_n as ordinary accessors (a new buffer holding their bytes), before
the importer counts the JOINTS_n sets, so the vertex groups are built as for any skinned file
and the mesh opens with exactly what a Skinpack-aware runtime would use.

Blender's importer prints and swallows an Exception raised in a hook and goes on, which would
import the mesh without its skin. A file that breaks a rule therefore raises ImportRefused,
which is not an Exception: the import stops before any object exists, naming the file, mesh,
primitive and the library's message. Here only the glTF layer is read (accessor types and
bounds, which skins and primitives share the arrays); every format rule is the library's.
"""

import numpy as np

from ...io import extension as ext
from ...io import native
from ..com import gltf2_skinpack_io as gltf_api


class ImportRefused(BaseException):
    """The file breaks a rule of SKINPACK_packed_skin: the import stops, nothing is created.
    A BaseException because the glTF importer swallows every Exception raised in a hook."""


class _Refusal(Exception):
    """A problem with one primitive; decode_file adds the file, mesh and primitive."""


# Component types the glTF layer accepts per array (the library checks the widths it implies).
_WORD_TYPES = (ext.COMPONENT_UNSIGNED_INT,)
_TABLE_TYPES = (ext.COMPONENT_UNSIGNED_BYTE, ext.COMPONENT_UNSIGNED_SHORT)
# meshlets property -> (the library's array name, component type, components; None: K).
_MESHLET_ACCESSORS = {"offsets": ("offsets", ext.COMPONENT_UNSIGNED_INT, 4),
                      "counts": ("counts", ext.COMPONENT_UNSIGNED_SHORT, 4),
                      "vertices": ("vertices", ext.COMPONENT_UNSIGNED_INT, 1),
                      "vertexTuples": ("vertex_tuples", ext.COMPONENT_UNSIGNED_BYTE, 1),
                      "triangles": ("triangles", ext.COMPONENT_UNSIGNED_BYTE, 1),
                      "joints": ("joints", ext.COMPONENT_UNSIGNED_SHORT, 1),
                      "tuples": ("tuples", ext.COMPONENT_UNSIGNED_BYTE, None)}
_MESHLET_LIMITS = {"maxVertices": "max_vertices", "maxTriangles": "max_triangles", "maxJoints": "max_joints"}


def _accessor(gltf, index, name, component_types):
    """(accessor, data (count, components)) of an accessor the extension references."""
    from io_scene_gltf2.io.imp.gltf2_io_binary import BinaryData
    accessors = gltf.data.accessors or []
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(accessors):
        raise _Refusal("%s: %r is not an accessor index" % (name, index))
    accessor = accessors[index]
    if accessor.component_type not in component_types:
        raise _Refusal("%s: accessor %d has component type %s, expected %s"
                       % (name, index, accessor.component_type, " or ".join(map(str, component_types))))
    if accessor.sparse is not None or accessor.normalized:
        raise _Refusal("%s: accessor %d must be neither sparse nor normalized" % (name, index))
    try:
        return accessor, np.asarray(BinaryData.decode_accessor(gltf, index))
    except (ValueError, TypeError, IndexError, KeyError, AssertionError) as error:
        raise _Refusal("%s: accessor %d lies outside its bufferView or buffer (%s)" % (name, index, error)) from None


def _meshlets(gltf, extension, influences):
    """The meshlet arrays and limits as native.validate_packed takes them, or None."""
    meshlets = extension.get("meshlets")
    if meshlets is None:
        return None
    if not isinstance(meshlets, dict):
        raise _Refusal("meshlets: not an object")
    arrays = {}
    for name, (field, component_type, components) in _MESHLET_ACCESSORS.items():
        if name not in meshlets:
            raise _Refusal("meshlets.%s is missing" % name)
        accessor, arrays[field] = _accessor(gltf, meshlets[name], "meshlets." + name, (component_type,))
        expected = ext.VECTOR_TYPES.get(components or influences)
        if accessor.type != expected:
            raise _Refusal("meshlets.%s: accessor %d is %s, expected %s" % (name, meshlets[name], accessor.type,
                                                                             expected))
    for name, field in _MESHLET_LIMITS.items():
        if name in meshlets:
            arrays[field] = native.json_integer(meshlets[name], "meshlets." + name, bits=32)
    return arrays


def _skin_joint_count(gltf, mesh_index):
    """Joints of the smallest skin of the nodes that use the mesh (0 when no node has a skin)."""
    skins = gltf.data.skins or []
    counts = [len(skins[node.skin].joints) for node in (gltf.data.nodes or [])
              if node.mesh == mesh_index and node.skin is not None and 0 <= node.skin < len(skins)]
    return min(counts) if counts else 0


def validate_primitive(gltf, mesh_index, primitive, extension):
    """(params, joints (V, K), weights (V, K)) of one packed primitive, validated and decoded
    by the library; raises _Refusal with its message."""
    if not isinstance(extension, dict):
        raise _Refusal("the extension is not an object")
    try:
        params = native.packed_params(extension)
        words_accessor, words = _accessor(gltf, extension.get("vertices"), "vertices", _WORD_TYPES)
        table_accessor, table = _accessor(gltf, extension.get("tupleTable"), "tupleTable", _TABLE_TYPES)
        position = (primitive.attributes or {}).get("POSITION")
        if position is None:
            raise _Refusal("the primitive has no POSITION")
        joints, weights, _ = native.validate_packed(
            params, words, words.shape[1], gltf.data.accessors[position].count, table,
            1 if table_accessor.component_type == ext.COMPONENT_UNSIGNED_BYTE else 2,
            _skin_joint_count(gltf, mesh_index), _meshlets(gltf, extension, int(params.influences)))
    except native.SkinpackError as error:
        raise _Refusal(str(error)) from None
    return params, joints, weights


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


def replace_skin_attributes(gltf, primitive, joints, weights):
    """JOINTS_0/WEIGHTS_0 := the decoded skin, padded to VEC4 (an unused slot has weight 0)."""
    vertex_count, K = weights.shape
    padded_joints = np.zeros((vertex_count, 4), dtype="<u2")
    padded_weights = np.zeros((vertex_count, 4), dtype="<f4")
    padded_joints[:, :K] = joints
    padded_weights[:, :K] = weights
    for key in [k for k in primitive.attributes if k.startswith(("JOINTS_", "WEIGHTS_"))]:
        del primitive.attributes[key]
    primitive.attributes["JOINTS_0"] = _append_accessor(gltf, padded_joints, ext.COMPONENT_UNSIGNED_SHORT, 4)
    primitive.attributes["WEIGHTS_0"] = _append_accessor(gltf, padded_weights, ext.COMPONENT_FLOAT, 4)


def decode_file(gltf):
    """Validates every packed primitive of the file, then (only if all pass) replaces their
    skin attributes. Raises ImportRefused naming the file, mesh and primitive."""
    decoded = []
    first_params = {}  # "vertices" accessor -> (params, where): sharing primitives must agree
    for mesh_index, mesh in enumerate(gltf.data.meshes or []):
        for primitive_index, primitive in enumerate(mesh.primitives):
            extension = (primitive.extensions or {}).get(ext.EXTENSION_NAME)
            if extension is None:
                continue
            where = "mesh %r (%d) primitive %d" % (mesh.name or "", mesh_index, primitive_index)
            try:
                if native.load() is None:
                    raise _Refusal(native.load_error())
                params, joints, weights = validate_primitive(gltf, mesh_index, primitive, extension)
                shared = first_params.setdefault(extension["vertices"], (params, where, extension.get("tupleTable")))
                if shared[1] != where and not native.params_equal(shared[0], params):
                    raise _Refusal("shares its vertices accessor with %s but declares other properties" % shared[1])
                if shared[1] != where and shared[2] != extension.get("tupleTable"):
                    raise _Refusal("shares its vertices accessor with %s but declares another tupleTable" % shared[1])
            except _Refusal as error:
                raise ImportRefused("Skinpack: %s: %s: %s" % (getattr(gltf, "filename", "?"), where, error)) from None
            decoded.append((primitive, joints, weights))
    for primitive, joints, weights in decoded:
        replace_skin_attributes(gltf, primitive, joints, weights)


class glTF2ImportUserExtension:
    def __init__(self):
        # A required extension must be declared, or the importer refuses the file.
        Extension = gltf_api.extension_class()
        self.extensions = [Extension(name=ext.EXTENSION_NAME, extension={}, required=True)]

    def gather_import_gltf_before_hook(self, gltf):
        decode_file(gltf)
