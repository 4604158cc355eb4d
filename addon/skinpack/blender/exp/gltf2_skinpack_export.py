"""glTF export user extension: writes SKINPACK_packed_skin for every skinned primitive.

Blender's exporter has no per-primitive hook. gather_mesh_hook remembers which Blender mesh
(and so which Skinpack settings) each glTF mesh came from; gather_gltf_hook then walks the
finished scene graph, where every skinned node knows its skin and so the joint count
(including the neutral joint the exporter adds for unweighted vertices), reads the exporter's
own JOINTS_n/WEIGHTS_n accessors and compresses them with the library. Binary data added
there is still laid out into the buffer (gather_gltf_extensions_hook would be too late).

An exception in a hook is swallowed by the exporter (3.4), so problems are collected in
`last_report` and the one-click operator turns them into an error.
"""

import bpy
import numpy as np

from ... import native, preview
from ..com import gltf2_skinpack_io as io

# One entry per compressed primitive ({"mesh", "stats"}) or failure ({"mesh", "error"}) of
# the latest export, for the operator and the tests.
last_report = []


def _read_accessor(accessor):
    dtype = io.NUMPY_COMPONENTS[int(accessor.component_type)]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[str(accessor.type)]
    data = np.frombuffer(accessor.buffer_view.data, dtype=dtype, count=accessor.count * width,
                         offset=accessor.byte_offset or 0)
    return data.reshape(accessor.count, width)


def _skin_arrays(attributes):
    """(joints (V, 4n) uint16, weights (V, 4n) float32) from JOINTS_0..n / WEIGHTS_0..n."""
    joints, weights = [], []
    index = 0
    while "JOINTS_%d" % index in attributes and "WEIGHTS_%d" % index in attributes:
        joints.append(_read_accessor(attributes["JOINTS_%d" % index]).astype(np.uint16))
        accessor = attributes["WEIGHTS_%d" % index]
        values = _read_accessor(accessor).astype(np.float32)
        if accessor.normalized:
            values = values / io.NORMALIZED_SCALE[int(accessor.component_type)]
        weights.append(values)
        index += 1
    if not joints:
        return None, None
    return np.concatenate(joints, axis=1), np.concatenate(weights, axis=1)


def _accessor(data, component_type, width, bounds=False):
    """An accessor on its own bufferView (no target: these are not bindable vertex attributes)."""
    gltf2_io = io.gltf_io()
    BinaryData = io.binary_data_class()
    data = np.ascontiguousarray(data)
    rows = data.reshape(-1, width)
    minimum = maximum = None
    if bounds and len(rows):
        # Python floats: the exporter's Accessor.to_dict asserts float bounds (and no numpy scalars).
        minimum = [float(v) for v in rows.min(axis=0)]
        maximum = [float(v) for v in rows.max(axis=0)]
    return gltf2_io.Accessor(buffer_view=BinaryData(data.tobytes()), byte_offset=None,
                             component_type=component_type, count=int(len(rows)), extensions=None,
                             extras=None, max=maximum, min=minimum, name=None, normalized=None, sparse=None,
                             type=io.VECTOR_TYPES[width])


def _placeholder_accessor(component_type, count):
    """Compact mode: JOINTS_0/WEIGHTS_0 stay in attributes as accessors without a bufferView
    (count, componentType, type only), as KHR_draco_mesh_compression does, so validators and
    readers still see a skinned mesh; the data comes from the extension."""
    gltf2_io = io.gltf_io()
    return gltf2_io.Accessor(buffer_view=None, byte_offset=None, component_type=component_type, count=int(count),
                             extensions=None, extras=None, max=None, min=None, name=None, normalized=None,
                             sparse=None, type="VEC4")


def extension_json(compressed, joint_count):
    """The extension object of docs/extension/CONTRACT.md (accessors still as objects)."""
    skin = compressed.skin
    K = int(skin.influences)
    words_per_vertex = int(skin.words_per_vertex)
    if joint_count <= 256:
        lut = compressed.lut.astype("<u1")
        lut_type = io.COMPONENT_UNSIGNED_BYTE
    else:
        lut = compressed.lut.astype("<u2")
        lut_type = io.COMPONENT_UNSIGNED_SHORT
    data = {
        "vertices": _accessor(compressed.words.astype("<u4"), io.COMPONENT_UNSIGNED_INT, words_per_vertex),
        "tupleTable": _accessor(lut, lut_type, K, bounds=True),
        "influences": K,
        "jointCount": int(joint_count),
        "method": compressed.method,
        "n": int(skin.codec.n),
        "weightBits": int(skin.weight_bits),
        "tupleBits": int(skin.tuple_bits),
        "maxError": float(skin.codec.max_error),
    }
    if compressed.method == "any":
        data["axisSamples"] = compressed.axis_samples()
    return data


def _drop_heat_map(gltf_mesh, blender_mesh):
    """The exporter writes the render colour attribute as COLOR_0; when that is one of Skinpack's
    previews (error heat map, meshlets) it is a visualisation, not content, and stays out of the file."""
    colors = blender_mesh.color_attributes
    index = colors.render_color_index
    if 0 <= index < len(colors) and colors[index].name in preview.ATTRIBUTE_NAMES:
        for primitive in gltf_mesh.primitives:
            primitive.attributes.pop("COLOR_0", None)


def _walk(nodes):
    for node in nodes or ():
        yield node
        yield from _walk(node.children)


class glTF2ExportUserExtension:
    def __init__(self):
        settings = bpy.context.scene.skinpack_export
        self.enabled = settings.enabled
        self.compact = settings.mode == 'COMPACT'
        self.mesh_settings = {}  # id(glTF mesh) -> (Blender mesh name, SkinpackMeshSettings)
        self.done = {}  # id(primitive attributes) -> Extension, so shared attribute dicts compress once

    def gather_mesh_hook(self, gltf_mesh, blender_mesh, *args):
        # args end with export_settings; the middle changed between versions (skip_filter).
        if gltf_mesh is None or not isinstance(blender_mesh, bpy.types.Mesh):
            return
        _drop_heat_map(gltf_mesh, blender_mesh)
        if self.enabled:
            self.mesh_settings[id(gltf_mesh)] = (blender_mesh.name, blender_mesh.skinpack)

    def gather_gltf_hook(self, active_scene_idx, scenes, animations, export_settings):
        last_report.clear()
        if not self.enabled:
            return
        if native.load() is None:
            last_report.append({"mesh": "", "error": native.load_error()})
            print("Skinpack: %s" % native.load_error())
            return
        # A mesh used by several skinned nodes is compressed once, with the largest joint count.
        joint_counts = {}
        meshes = {}
        for scene in scenes:
            for node in _walk(scene.nodes):
                if node.mesh is not None and node.skin is not None:
                    key = id(node.mesh)
                    meshes[key] = node.mesh
                    joint_counts[key] = max(joint_counts.get(key, 0), len(node.skin.joints))
        for key, mesh in meshes.items():
            for primitive in mesh.primitives:
                self._compress_primitive(mesh, primitive, joint_counts[key])

    def _compress_primitive(self, mesh, primitive, joint_count):
        from ...operators import compression_options
        Extension = io.extension_class()
        name, settings = self.mesh_settings.get(id(mesh), (mesh.name or "", None))
        cache_key = id(primitive.attributes)
        if cache_key in self.done:
            extension = self.done[cache_key]
        else:
            joints, weights = _skin_arrays(primitive.attributes)
            if joints is None:
                return
            try:
                if settings is None:
                    options = native.make_options("oss", 4, vertex_bits=32)
                else:
                    options = compression_options(settings, weights.shape[1])
                compressed = native.compress(joints, weights, joint_count, options)
            except (native.SkinpackError, ValueError) as error:
                message = "%s: %s" % (name, error)
                last_report.append({"mesh": name, "error": message})
                print("Skinpack: primitive left uncompressed: %s" % message)
                return
            extension = Extension(io.EXTENSION_NAME, extension_json(compressed, joint_count), required=self.compact)
            self.done[cache_key] = extension
            stats = native.stats_dict(compressed)
            last_report.append({"mesh": name, "stats": stats})
            if self.compact:
                for key in [k for k in primitive.attributes if k.startswith(("JOINTS_", "WEIGHTS_"))]:
                    del primitive.attributes[key]
                joint_type = io.COMPONENT_UNSIGNED_BYTE if joint_count <= 256 else io.COMPONENT_UNSIGNED_SHORT
                primitive.attributes["JOINTS_0"] = _placeholder_accessor(joint_type, len(joints))
                primitive.attributes["WEIGHTS_0"] = _placeholder_accessor(io.COMPONENT_FLOAT, len(joints))
        if primitive.extensions is None:
            primitive.extensions = {}
        primitive.extensions[io.EXTENSION_NAME] = extension


class SKINPACK_PT_gltf_export(bpy.types.Panel):
    """Skinpack options inside the glTF exporter's file browser (Blender up to 4.1)."""
    bl_space_type = 'FILE_BROWSER'
    bl_region_type = 'TOOL_PROPS'
    bl_label = "Skinpack"
    bl_parent_id = "GLTF_PT_export_user_extensions"
    bl_options = {'DEFAULT_CLOSED'}

    @classmethod
    def poll(cls, context):
        operator = context.space_data.active_operator
        return operator is not None and operator.bl_idname == "EXPORT_SCENE_OT_gltf"

    def draw_header(self, context):
        self.layout.prop(context.scene.skinpack_export, "enabled", text="")

    def draw(self, context):
        draw_settings(self.layout, context)


def draw_settings(layout, context):
    settings = context.scene.skinpack_export
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.active = settings.enabled
    layout.prop(settings, "mode")
    layout.label(text="Codec and budget: each mesh's Skinpack panel")


def draw_export_layout(context, layout):
    """Blender 4.2+: the exporter calls this from its own panel."""
    header, body = layout.panel("SKINPACK_gltf_export", default_closed=True)
    header.use_property_split = False
    header.prop(context.scene.skinpack_export, "enabled", text="Skinpack")
    if body is not None:
        draw_settings(body, context)


def register_panel():
    """Called by the glTF exporter (up to 4.1) each time its file browser opens."""
    if not SKINPACK_PT_gltf_export.is_registered:
        bpy.utils.register_class(SKINPACK_PT_gltf_export)
    return unregister_panel


def unregister_panel():
    if SKINPACK_PT_gltf_export.is_registered:
        bpy.utils.unregister_class(SKINPACK_PT_gltf_export)


def register():
    if bpy.app.version >= (4, 2, 0):
        try:
            import io_scene_gltf2
            io_scene_gltf2.exporter_extension_layout_draw["Skinpack"] = draw_export_layout
        except (ImportError, AttributeError):
            pass


def unregister():
    unregister_panel()
    if bpy.app.version >= (4, 2, 0):
        try:
            import io_scene_gltf2
            io_scene_gltf2.exporter_extension_layout_draw.pop("Skinpack", None)
        except (ImportError, AttributeError):
            pass
