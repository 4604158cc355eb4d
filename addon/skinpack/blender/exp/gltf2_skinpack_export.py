"""glTF export user extension: writes SKINPACK_packed_skin for the skinned meshes, when asked.

Opt-in: nothing is compressed unless the scene's Skinpack export setting is on (off by
default; the one-click Export Compressed glTF operator turns it on for its own export).

Blender's exporter has no per-primitive hook. gather_mesh_hook copies what it needs at once,
as plain values: the object's name, its mesh's Skinpack settings and the exporter's own
JOINTS_n/WEIGHTS_n arrays (with Apply Modifiers the mesh it gets is a temporary copy that is
freed before the export ends). gather_gltf_hook then walks the finished scene graph, where every
skinned node knows its skin and so the joint count (including the neutral joint the exporter
adds for unweighted vertices), compresses with the library and adds the binary data while it
is still laid out into the buffer.

Around every export (module-level callbacks on the add-on, skinpack/__init__.py):
- the pre-export callback takes Skinpack's preview colour attributes off the meshes, so no
  colour setting of any version writes them, and refuses Draco (Draco reorders the vertices
  after our arrays were read, so the extension would not match the file's vertices);
- the post-export callback, which runs before the file is written, puts the previews back and
  fails the export when a Compact export could not compress every skinned primitive.
Problems are reported by object name through export_settings['log'] (4.2+, with a popup),
the console, `last_report` (the operator and the panel read it) and `is_critical` (5.2+).
"""

import bpy
import numpy as np

from ... import preview, skin_services
from ...io import extension as ext
from ...io import native
from ..com import gltf2_skinpack_io as gltf_api


class ExportReport:
    """What the latest export compressed, pruned and refused, by object name."""

    def __init__(self):
        self.compressed = []  # (object name, stats dict)
        self.errors = []  # messages naming the object
        self.compact = False

    def clear(self, compact=False):
        self.compressed.clear()
        self.errors.clear()
        self.compact = compact

    def warnings(self):
        return ["%s: %s" % (name, skin_services.pruning_text(stats))
                for name, stats in self.compressed if stats["pruned_vertices"]]

    def summary(self):
        if not self.compressed:
            return "no skinned primitive compressed"
        names = sorted({name for name, _ in self.compressed})
        return "%d skinned primitives compressed (%s): %s" % (
            len(self.compressed), "compact" if self.compact else "fallback", ", ".join(names))


# The latest export's report, for the operator, the panel and the tests.
last_report = ExportReport()


def _read_accessor(accessor):
    dtype = ext.NUMPY_COMPONENTS[int(accessor.component_type)]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[str(accessor.type)]
    data = np.frombuffer(accessor.buffer_view.data, dtype=dtype, count=accessor.count * width,
                         offset=accessor.byte_offset or 0)
    return data.reshape(accessor.count, width)


def _skin_arrays(attributes):
    """Copies of (joints (V, 4n) uint16, weights (V, 4n) float32) from every JOINTS_n/WEIGHTS_n
    (all influences, whatever the exporter's influence setting wrote), or (None, None)."""
    joints, weights = [], []
    index = 0
    while "JOINTS_%d" % index in attributes and "WEIGHTS_%d" % index in attributes:
        joint_accessor = attributes["JOINTS_%d" % index]
        accessor = attributes["WEIGHTS_%d" % index]
        if joint_accessor.buffer_view is None or accessor.buffer_view is None:
            return None, None  # already compressed (a shared attributes dict) or encoded by others
        joints.append(_read_accessor(joint_accessor).astype(np.uint16))
        values = _read_accessor(accessor).astype(np.float32)
        if accessor.normalized:
            values = values / ext.NORMALIZED_SCALE[int(accessor.component_type)]
        weights.append(values)
        index += 1
    if not joints:
        return None, None
    return np.concatenate(joints, axis=1), np.concatenate(weights, axis=1)


def _accessor(field):
    """An accessor on its own bufferView (no target: these are not bindable vertex attributes)."""
    gltf2_io = gltf_api.gltf_io()
    BinaryData = gltf_api.binary_data_class()
    rows = field.data.reshape(-1, field.width)
    minimum = maximum = None
    if field.bounds and len(rows):
        # Python floats: the exporter's Accessor.to_dict asserts float bounds (and no numpy scalars).
        minimum = [float(v) for v in rows.min(axis=0)]
        maximum = [float(v) for v in rows.max(axis=0)]
    return gltf2_io.Accessor(buffer_view=BinaryData(field.data.tobytes()), byte_offset=None,
                             component_type=field.component_type, count=int(len(rows)), extensions=None,
                             extras=None, max=maximum, min=minimum, name=None, normalized=None, sparse=None,
                             type=ext.VECTOR_TYPES[field.width])


def _placeholder_accessor(component_type, count):
    """Compact mode: JOINTS_0/WEIGHTS_0 stay in attributes (count, componentType, type), so
    validators and readers still see a skinned mesh; the data comes from the extension. Their
    bufferViews are added in the fallback buffer once the exporter has laid out its own."""
    gltf2_io = gltf_api.gltf_io()
    return gltf2_io.Accessor(buffer_view=None, byte_offset=None, component_type=component_type, count=int(count),
                             extensions=None, extras=None, max=None, min=None, name=None, normalized=None,
                             sparse=None, type="VEC4")


def add_fallback_buffer(gltf, placeholders):
    """Gives the placeholder accessors bufferViews in a new data-less fallback buffer (the CLI's
    compact layout, docs/extension/loaders.md). Runs after the exporter's buffer is final: the
    fallback buffer is never buffer 0, which in a GLB is the BIN chunk."""
    if not placeholders or not gltf.buffers:
        return  # no buffer 0: the views stay unset and post_export refuses the export
    gltf2_io = gltf_api.gltf_io()
    lengths = [ext.accessor_byte_length(a.component_type, 4, a.count) for a in placeholders]
    offsets, byte_length = ext.fallback_layout(lengths)
    buffer_index = len(gltf.buffers)
    gltf.buffers.append(gltf2_io.Buffer(byte_length=byte_length, extensions=dict(ext.FALLBACK_BUFFER_EXTENSIONS),
                                        extras=None, name=None, uri=None))
    for accessor, offset, length in zip(placeholders, offsets, lengths):
        accessor.buffer_view = len(gltf.buffer_views)
        gltf.buffer_views.append(gltf2_io.BufferView(buffer=buffer_index, byte_length=length, byte_offset=offset,
                                                     byte_stride=None, extensions=None, extras=None, name=None,
                                                     target=None))


def extension_json(compressed, joint_count):
    """The extension object of docs/extension/CONTRACT.md, arrays as exporter accessors."""
    fields = ext.extension_fields(compressed, joint_count)
    return {key: _accessor(value) if isinstance(value, ext.ArrayField) else value for key, value in fields.items()}


def _walk(nodes):
    for node in nodes or ():
        yield node
        yield from _walk(node.children)


def _log(export_settings, level, message):
    """Blender 4.2+: the exporter's log, shown in a popup; always the console too."""
    print("Skinpack: %s" % message)
    log = export_settings.get("log")
    if log is not None:
        getattr(log, level)("Skinpack: %s" % message, popup=True)


def _our_extension(export_settings):
    for extension in export_settings.get("gltf_user_extensions", ()):
        if isinstance(extension, glTF2ExportUserExtension):
            return extension
    return None


class MeshSource:
    """Plain copies, taken in gather_mesh_hook, of what the compression of one glTF mesh needs."""

    def __init__(self, object_name, settings):
        self.object_name = object_name
        self.settings = settings  # SkinpackMeshSettings.options_summary() of the object's mesh
        self.arrays = {}  # id(primitive.attributes) -> (joints, weights)


class glTF2ExportUserExtension:
    def __init__(self):
        settings = bpy.context.scene.skinpack_export
        self.enabled = settings.enabled
        self.compact = settings.mode == 'COMPACT'
        self.is_critical = False  # Blender 5.2+ aborts the export when this is set
        self.sources = {}  # id(glTF mesh) -> MeshSource
        self.done = {}  # id(primitive attributes) -> Extension, so shared attribute dicts compress once
        self.placeholders = []  # (object name, compact JOINTS_0/WEIGHTS_0 accessor): fallback views come last
        last_report.clear(self.compact)

    def gather_mesh_hook(self, gltf_mesh, blender_mesh, blender_object, *args):
        # args end with export_settings; the middle changed between versions (skip_filter).
        if not self.enabled or gltf_mesh is None or id(gltf_mesh) in self.sources:
            return
        owner = blender_object.data if getattr(blender_object, "type", None) == 'MESH' else blender_mesh
        if not isinstance(owner, bpy.types.Mesh):
            return
        name = blender_object.name if blender_object is not None else owner.name
        source = MeshSource(name, owner.skinpack.options_summary())
        for primitive in gltf_mesh.primitives:
            joints, weights = _skin_arrays(primitive.attributes)
            if joints is not None:
                source.arrays[id(primitive.attributes)] = (joints, weights)
        self.sources[id(gltf_mesh)] = source

    def gather_gltf_hook(self, active_scene_idx, scenes, animations, export_settings):
        if not self.enabled:
            return
        if native.load() is None:
            self.report_error(export_settings, native.load_error())
            return
        # A mesh used by several skinned nodes is compressed once, with the largest joint count.
        joint_counts, meshes = {}, {}
        for scene in scenes:
            for node in _walk(scene.nodes):
                if node.mesh is not None and node.skin is not None:
                    key = id(node.mesh)
                    meshes[key] = node.mesh
                    joint_counts[key] = max(joint_counts.get(key, 0), len(node.skin.joints))
        for key, mesh in meshes.items():
            source = self.sources.get(key)
            for primitive in mesh.primitives:
                self._compress_primitive(source, mesh, primitive, joint_counts[key], export_settings)
        for message in last_report.warnings():
            _log(export_settings, "warning", message)
        _log(export_settings, "info", last_report.summary())

    def gather_gltf_extensions_hook(self, gltf, export_settings):
        # The last hook, after the exporter laid out its buffer: JSON edits only (no binary).
        if self.enabled and self.compact:
            add_fallback_buffer(gltf, [accessor for _, accessor in self.placeholders])

    def report_error(self, export_settings, message):
        last_report.errors.append(message)
        self.is_critical = self.is_critical or self.compact
        _log(export_settings, "error", message)

    def _compress_primitive(self, source, mesh, primitive, joint_count, export_settings):
        cache_key = id(primitive.attributes)
        if cache_key not in self.done:
            arrays = source.arrays.get(cache_key) if source is not None else None
            if arrays is None:
                if "JOINTS_0" in primitive.attributes:
                    self.report_error(export_settings, "%s: the skin of a primitive could not be read; left "
                                      "uncompressed" % (mesh.name or "<unnamed mesh>"))
                return
            joints, weights = arrays
            try:
                compressed, stats = skin_services.compress_skin(source.object_name, joints, weights,
                                                                joint_count, source.settings)
            except (native.SkinpackError, ValueError) as error:
                self.report_error(export_settings, "%s; primitive left uncompressed" % error)
                return
            Extension = gltf_api.extension_class()
            self.done[cache_key] = Extension(ext.EXTENSION_NAME, extension_json(compressed, joint_count),
                                             required=self.compact)
            last_report.compressed.append((source.object_name, stats))
            if self.compact:
                self._drop_plain_skin(source.object_name, primitive, joint_count, len(joints))
        if primitive.extensions is None:
            primitive.extensions = {}
        primitive.extensions[ext.EXTENSION_NAME] = self.done[cache_key]

    def _drop_plain_skin(self, object_name, primitive, joint_count, vertex_count):
        for key in [k for k in primitive.attributes if k.startswith(("JOINTS_", "WEIGHTS_"))]:
            del primitive.attributes[key]
        joints = _placeholder_accessor(ext.joint_component(joint_count), vertex_count)
        weights = _placeholder_accessor(ext.COMPONENT_FLOAT, vertex_count)
        primitive.attributes["JOINTS_0"], primitive.attributes["WEIGHTS_0"] = joints, weights
        self.placeholders += [(object_name, joints), (object_name, weights)]


class ExportRefused(RuntimeError):
    """Raised from an export callback: the exporter stops and writes no file."""


# Previews taken off the meshes by the running export (module level: one export at a time).
_detached_previews = []


def pre_export(export_settings):
    """glTF2_pre_export_callback: previews off the meshes; Draco refused when Skinpack is on."""
    extension = _our_extension(export_settings)
    if extension is not None and extension.enabled and export_settings.get("gltf_draco_mesh_compression"):
        message = "Draco reorders vertices: turn off Draco or Skinpack (nothing written)"
        extension.report_error(export_settings, message)
        raise ExportRefused("Skinpack: " + message)
    _detached_previews.extend(preview.detach_previews(bpy.data.meshes))
    # An exporter error before post_export leaves them detached: the UI's next idle moment puts
    # them back (timers cannot run during the export, which holds the main thread).
    if _detached_previews and not bpy.app.timers.is_registered(_restore_after_failure):
        bpy.app.timers.register(_restore_after_failure, first_interval=0.1)


def _restore_after_failure():
    restore_previews()
    return None  # once


def post_export(export_settings):
    """glTF2_post_export_callback (before the file is written): previews back; a Compact export
    that left a skinned primitive uncompressed fails instead of writing a file without its skin."""
    restore_previews()
    extension = _our_extension(export_settings)
    if extension is None or not extension.enabled or not extension.compact:
        return
    unplaced = sorted({name for name, accessor in extension.placeholders if accessor.buffer_view is None})
    if unplaced:
        # The exporter swallows hook exceptions: without this the file would have the old,
        # zeros-reading layout (JOINTS_0/WEIGHTS_0 accessors without a bufferView).
        extension.report_error(export_settings, "%s: JOINTS_0/WEIGHTS_0 got no bufferView in the fallback buffer"
                               % ", ".join(unplaced))
    if last_report.errors:
        raise ExportRefused("Skinpack: Compact export not written: " + "; ".join(last_report.errors))


def restore_previews():
    """Puts back previews an export took off (also after a failed export: the operator, unregister)."""
    preview.reattach_previews(_detached_previews)


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
    layout.label(text="Draco must be off: it reorders the vertices")


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
    restore_previews()
    if bpy.app.timers.is_registered(_restore_after_failure):
        bpy.app.timers.unregister(_restore_after_failure)
    if bpy.app.version >= (4, 2, 0):
        try:
            import io_scene_gltf2
            io_scene_gltf2.exporter_extension_layout_draw.pop("Skinpack", None)
        except (ImportError, AttributeError):
            pass
