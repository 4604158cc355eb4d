"""Operators with stable ids for the panel, scripts and pipelines (all on the active object).

Every operator that touches mesh data leaves it bit-identical when it fails or is cancelled:
compression only reads the weights; the A/B toggle and the pose preview write weights only
after everything that can fail has succeeded, and write the originals back on any exception.
"""

import os
import time

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty

from . import gather, meshlet_preview, native, preview, properties, storage


def _active_mesh(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == 'MESH' else None


def _poll_mesh(context):
    obj = _active_mesh(context)
    return obj is not None and obj.mode != 'EDIT'


class _Progress:
    """window_manager.progress_* plus the status bar, both optional in background mode."""

    def __init__(self, context, steps):
        self.wm = context.window_manager
        self.workspace = context.workspace
        self.wm.progress_begin(0, steps)

    def step(self, index, text):
        self.wm.progress_update(index)
        if self.workspace is not None:
            self.workspace.status_text_set("Skinpack: " + text)

    def end(self):
        self.wm.progress_end()
        if self.workspace is not None:
            self.workspace.status_text_set(None)


def compression_options(settings, influences_available):
    """sp_compress_options from the mesh settings; raises ValueError for an unreachable target."""
    method = settings.method.lower()
    K = min(settings.max_influences, influences_available)
    if settings.budget == 'ERROR':
        bits = native.weight_bits_for_error(method, K, settings.max_error)
        if bits is None:
            raise ValueError("no %s configuration reaches a max error of %g" % (method, settings.max_error))
        return native.make_options(method, settings.max_influences, weight_bits=bits)
    bits = settings.custom_bits if settings.budget == 'CUSTOM' else int(settings.budget)
    return native.make_options(method, settings.max_influences, vertex_bits=bits)


def compress_object(obj):
    """Reads, compresses and stores; returns the stored result. Raises GatherError,
    SkinpackError or ValueError with messages that name the object."""
    skin = gather.gather(obj)
    settings = obj.data.skinpack
    try:
        options = compression_options(settings, skin.weights.shape[1])
        compressed = native.compress(skin.joints, skin.weights, len(skin.joint_names), options)
    except native.SkinpackError as error:
        if error.code in native.PER_VERTEX_ERRORS:
            detail = " (vertex %d)" % error.vertex
        else:
            detail = " (%s, %s)" % (settings.method.lower(), _budget_text(settings))
        raise native.SkinpackError("%s: %s%s" % (obj.name, error, detail), error.code, error.vertex)
    except ValueError as error:
        raise ValueError("%s: %s" % (obj.name, error))
    return storage.save_result(obj.data, compressed, skin, settings.options_summary())


def _budget_text(settings):
    if settings.budget == 'ERROR':
        return "max error %g" % settings.max_error
    bits = settings.custom_bits if settings.budget == 'CUSTOM' else int(settings.budget)
    return "%d bits per vertex for tuple index and weights" % bits


def stats_line(stats):
    return ("%s: %.1f -> %.1f bits/vertex (%.1fx), %d tuples, max error %.2e, RMS %.2e"
            % (stats["method"].upper(), stats["input_bits_per_vertex"], stats["bits_per_vertex"], stats["ratio"],
               stats["unique_tuples"], stats["max_error"], stats["rms_error"]))


class SKINPACK_OT_compress(bpy.types.Operator):
    """Compress the skin weights of the active mesh and store the result with the mesh"""
    bl_idname = "skinpack.compress"
    bl_label = "Compress"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context)

    def execute(self, context):
        obj = _active_mesh(context)
        if native.load() is None:
            self.report({'ERROR'}, native.load_error())
            return {'CANCELLED'}
        if storage.showing_decoded(obj.data):
            self.report({'ERROR'}, "%s shows the decoded weights (A/B); switch back to the originals first" % obj.name)
            return {'CANCELLED'}
        progress = _Progress(context, 2)
        start = time.perf_counter()
        try:
            progress.step(0, "compressing %s" % obj.name)
            result = compress_object(obj)
            progress.step(2, "done")
            if preview.legend(obj.data) is not None:
                # The heat map showed the previous result; it is redrawn from the new one.
                values, scale = preview.weight_errors(obj, result)
                preview.write_heat_map(obj, values, scale, 'WEIGHT')
        except (gather.GatherError, native.SkinpackError, ValueError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        self.report({'INFO'}, "%s: %s (%.2f s)" % (obj.name, stats_line(result.stats), time.perf_counter() - start))
        return {'FINISHED'}


class SKINPACK_OT_preview_error(bpy.types.Operator):
    """Show the per-vertex error of the stored compression as a heat map (colour attribute)"""
    bl_idname = "skinpack.preview_error"
    bl_label = "Preview Error"
    bl_options = {'REGISTER', 'UNDO'}

    mode: EnumProperty(name="Mode", default='WEIGHT', items=(
        ('WEIGHT', "Weight", "L-inf error over the vertex's weights (from the library)"),
        ('POSE', "Pose", "Distance between the vertex skinned with original and decoded weights, current pose"),
    ))

    @classmethod
    def poll(cls, context):
        obj = _active_mesh(context)
        return obj is not None and obj.mode != 'EDIT' and storage.RESULT_KEY in obj.data

    def execute(self, context):
        obj = _active_mesh(context)
        result = storage.load_result(obj.data)
        if result is None:
            self.report({'ERROR'}, "%s has no compression result; press Compress first" % obj.name)
            return {'CANCELLED'}
        progress = _Progress(context, 1)
        try:
            progress.step(0, "measuring the %s error of %s" % (self.mode.lower(), obj.name))
            if self.mode == 'WEIGHT':
                values, scale = preview.weight_errors(obj, result)
            else:
                values, scale = preview.pose_errors(context, obj, result)
        except (preview.PreviewError, gather.GatherError, native.SkinpackError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        preview.write_heat_map(obj, values, scale, self.mode)
        preview.show_in_viewports(context, obj.data)
        self.report({'INFO'}, "%s: %s, max %.3g" % (obj.name, preview.MODE_LABELS[self.mode], float(values.max())))
        return {'FINISHED'}


class SKINPACK_OT_preview_meshlets(bpy.types.Operator):
    """Split the active mesh into skin-aware meshlets with the library and colour its faces by meshlet"""
    bl_idname = "skinpack.preview_meshlets"
    bl_label = "Preview Meshlets"
    bl_options = {'REGISTER', 'UNDO'}

    mode: EnumProperty(name="Mode", default='MESHLET', items=properties.MESHLET_MODE_ITEMS)
    builder: EnumProperty(name="Builder", default='SKIN', items=properties.MESHLET_BUILDER_ITEMS)
    max_vertices: IntProperty(name="Max Vertices", default=64, min=3, max=255)
    max_triangles: IntProperty(name="Max Triangles", default=124, min=1, max=512)
    palette_size: IntProperty(name="Palette Size", default=32, min=1, max=255,
                              description="Distinct joints per meshlet")

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context)

    def execute(self, context):
        obj = _active_mesh(context)
        if native.load() is None:
            self.report({'ERROR'}, native.load_error())
            return {'CANCELLED'}
        builder = meshlet_preview.BUILDERS[self.builder]
        progress = _Progress(context, 2)
        try:
            progress.step(0, "reading %s" % obj.name)
            inputs = meshlet_preview.read_inputs(obj, obj.data.skinpack.max_influences)
            progress.step(1, "building %s meshlets of %s" % (builder, obj.name))
            options = native.meshlet_options(builder, self.max_vertices, self.max_triangles, self.palette_size)
            meshlets = meshlet_preview.build(obj, inputs, options)
        except (gather.GatherError, native.SkinpackError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        # Nothing is written to the mesh before this point, so a failure above leaves it untouched.
        meshlet_preview.write(obj, self.mode, inputs, meshlets, self.palette_size)
        preview.show_in_viewports(context, obj.data)
        stats = meshlet_preview.store_stats(obj, meshlets.stats, self.builder, self.mode)
        self.report({'INFO'}, "%s: %d %s meshlets, mean %.1f vertices, %.1f triangles, %.1f joints (max %d); "
                    "tuple index %d bits global, %.2f local" % (
                        obj.name, stats["meshlet_count"], builder, stats["mean_vertices"],
                        stats["mean_triangles"], stats["mean_joints"], stats["max_joints"],
                        stats["global_tuple_bits"], stats["local_tuple_bits_mean"]))
        return {'FINISHED'}


class SKINPACK_OT_clear_preview(bpy.types.Operator):
    """Remove the error heat map or meshlet colours and restore the viewport colouring"""
    bl_idname = "skinpack.clear_preview"
    bl_label = "Clear Preview"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return _active_mesh(context) is not None

    def execute(self, context):
        obj = _active_mesh(context)
        preview.clear(context, obj)
        obj.skinpack_meshlets.valid = False
        return {'FINISHED'}


class SKINPACK_OT_toggle_decoded(bpy.types.Operator):
    """Swap the mesh between its original and its decoded (compressed) weights to compare the deformation"""
    bl_idname = "skinpack.toggle_decoded"
    bl_label = "A/B Decoded Weights"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        obj = _active_mesh(context)
        return (obj is not None and obj.mode != 'EDIT'
                and (storage.RESULT_KEY in obj.data or storage.ORIGINAL_KEY in obj.data))

    def execute(self, context):
        obj = _active_mesh(context)
        mesh = obj.data
        progress = _Progress(context, 1)
        try:
            progress.step(0, "swapping the weights of %s" % obj.name)
            if storage.showing_decoded(mesh):
                restore_originals(obj)
                self.report({'INFO'}, "%s: original weights restored" % obj.name)
            else:
                show_decoded(obj)
                self.report({'INFO'}, "%s: showing decoded weights" % obj.name)
        except (gather.GatherError, native.SkinpackError, preview.PreviewError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        mesh.update()
        return {'FINISHED'}


def show_decoded(obj):
    mesh = obj.data
    result = storage.load_result(mesh)
    if result is None or storage.is_stale(mesh, result):
        raise preview.PreviewError("%s: no up-to-date compression result; press Compress first" % obj.name)
    skin = gather.gather(obj)
    if not storage.matches_weights(result, skin):
        raise preview.PreviewError("%s: the weights or deform bones changed since compression; compress again"
                                   % obj.name)
    decoded_joints, decoded_weights = result.decode()
    decoded = gather.decoded_element_weights(skin, decoded_joints, decoded_weights)
    storage.save_originals(mesh, skin.element_counts, skin.element_groups, skin.element_weights)
    try:
        gather.write_element_weights(mesh, skin.element_counts, decoded, skin.element_weights)
    except Exception:
        # Whatever was written so far goes back; unchanged elements are skipped.
        _, _, partial = gather.read_elements(mesh)
        gather.write_element_weights(mesh, skin.element_counts, skin.element_weights, partial)
        storage.clear_originals(mesh)
        raise


def restore_originals(obj):
    mesh = obj.data
    counts, groups, weights = storage.load_originals(mesh)
    current_counts, current_groups, current_weights = gather.read_elements(mesh)
    if not (len(counts) == len(current_counts) and (counts == current_counts).all()
            and (groups == current_groups).all()):
        raise preview.PreviewError("%s: vertices or group memberships changed while the decoded weights were "
                                   "shown; originals kept in the mesh's '%s' property" % (obj.name, storage.ORIGINAL_KEY))
    gather.write_element_weights(mesh, counts, weights, current_weights)
    storage.clear_originals(mesh)


class SKINPACK_OT_export_gltf(bpy.types.Operator):
    """Export the active object and its armature as glTF with SKINPACK_packed_skin (Blender's glTF exporter)"""
    bl_idname = "skinpack.export_gltf"
    bl_label = "Export Compressed glTF"
    bl_options = {'REGISTER'}

    filepath: StringProperty(name="File Path", subtype='FILE_PATH')
    filter_glob: StringProperty(default="*.glb;*.gltf", options={'HIDDEN'})
    mode: EnumProperty(name="Mode", default='FALLBACK', items=(
        ('FALLBACK', "Fallback", "Keep JOINTS_0/WEIGHTS_0 (extension optional)"),
        ('COMPACT', "Compact", "Drop JOINTS_0/WEIGHTS_0 (extension required)"),
    ))

    @classmethod
    def poll(cls, context):
        return _poll_mesh(context)

    def invoke(self, context, event):
        if not self.filepath:
            blend = bpy.data.filepath
            base = os.path.splitext(blend)[0] if blend else os.path.join(os.path.expanduser("~"), "untitled")
            self.filepath = base + ".glb"
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context):
        from .blender.exp import gltf2_skinpack_export as exporter
        obj = _active_mesh(context)
        if not self.filepath:
            self.report({'ERROR'}, "No file path given")
            return {'CANCELLED'}
        if native.load() is None:
            self.report({'ERROR'}, native.load_error())
            return {'CANCELLED'}
        if 'io_scene_gltf2' not in context.preferences.addons:
            self.report({'ERROR'}, "Enable Blender's glTF 2.0 add-on (io_scene_gltf2) first")
            return {'CANCELLED'}
        armature = gather.find_armature(obj)
        if armature is None:
            self.report({'ERROR'}, "%s is not deformed by an armature" % obj.name)
            return {'CANCELLED'}
        export = context.scene.skinpack_export
        saved_settings = (export.enabled, export.mode)
        saved_selection = [(o, o.select_get()) for o in context.view_layer.objects]
        filepath = bpy.path.abspath(self.filepath)
        export_format = 'GLTF_SEPARATE' if filepath.lower().endswith(".gltf") else 'GLB'
        try:
            export.enabled, export.mode = True, self.mode
            for o, _ in saved_selection:
                o.select_set(o == obj or o == armature)
            exporter.last_report.clear()
            bpy.ops.export_scene.gltf(filepath=filepath, export_format=export_format, use_selection=True)
        except RuntimeError as error:
            self.report({'ERROR'}, "glTF export of %s failed: %s" % (obj.name, str(error).strip().splitlines()[-1]))
            return {'CANCELLED'}
        finally:
            export.enabled, export.mode = saved_settings
            for o, selected in saved_selection:
                o.select_set(selected)
        report = list(exporter.last_report)
        if not report or any("error" in entry for entry in report):
            problems = "; ".join(entry.get("error", "") for entry in report) or "no skinned primitive found"
            self.report({'ERROR'}, "%s written without SKINPACK_packed_skin: %s" % (filepath, problems))
            return {'CANCELLED'}
        self.report({'INFO'}, "%s: %d skinned primitives compressed (%s)" % (filepath, len(report), self.mode.lower()))
        return {'FINISHED'}


classes = (SKINPACK_OT_compress, SKINPACK_OT_preview_error, SKINPACK_OT_preview_meshlets,
           SKINPACK_OT_clear_preview, SKINPACK_OT_toggle_decoded, SKINPACK_OT_export_gltf)


register, unregister = bpy.utils.register_classes_factory(classes)
