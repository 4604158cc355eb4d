"""Operators with stable ids for the panel, scripts and pipelines (all on the active object).

Every operator that touches mesh data leaves it bit-identical when it fails or is cancelled:
compression only reads the weights; the A/B toggle and the pose preview write weights only
after everything that can fail has succeeded, and write the originals back on any exception.
"""

import os
import time

import bpy
from bpy.props import EnumProperty, StringProperty

from . import gather, meshlet_preview, preview, properties, skin_services
from .io import native, storage


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
            result = skin_services.compress_object(obj)
            progress.step(2, "done")
            if preview.legend(obj.data) is not None:
                # The heat map showed the previous result; it is redrawn from the new one.
                values, scale, extra = preview.weight_errors(obj, result)
                preview.write_heat_map(obj, values, scale, 'WEIGHT', extra)
        except (gather.GatherError, native.SkinpackError, ValueError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        self.report({'INFO'}, "%s: %s (%.2f s)" % (obj.name, skin_services.stats_line(result.stats),
                                                  time.perf_counter() - start))
        pruning = skin_services.pruning_text(result.stats)
        if pruning:
            self.report({'WARNING'}, "%s: %s" % (obj.name, pruning))
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
                values, scale, extra = preview.weight_errors(obj, result)
            else:
                values, scale, extra = preview.pose_errors(context, obj, result)
        except (preview.PreviewError, gather.GatherError, native.SkinpackError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        preview.write_heat_map(obj, values, scale, self.mode, extra)
        preview.show_in_viewports(context, obj.data)
        label = preview.mode_label(obj.data[storage.PREVIEW_KEY])
        self.report({'INFO'}, "%s: %s, max %.3g" % (obj.name, label, float(values.max())))
        return {'FINISHED'}


class SKINPACK_OT_preview_meshlets(bpy.types.Operator):
    """Split the active mesh into skin-aware meshlets with the library and colour its faces by meshlet"""
    bl_idname = "skinpack.preview_meshlets"
    bl_label = "Preview Meshlets"
    bl_options = {'REGISTER', 'UNDO'}

    mode: EnumProperty(name="Mode", default='MESHLET', items=properties.MESHLET_MODE_ITEMS)
    builder: EnumProperty(name="Builder", default=properties.DEFAULTS["builder"],
                          items=properties.MESHLET_BUILDER_ITEMS)
    max_vertices: properties.meshlet_limit_properties()["max_vertices"]
    max_triangles: properties.meshlet_limit_properties()["max_triangles"]
    palette_size: properties.meshlet_limit_properties()["palette_size"]
    palette_effort: properties.meshlet_limit_properties()["palette_effort"]

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
            options = native.meshlet_options(builder, self.max_vertices, self.max_triangles, self.palette_size,
                                             self.palette_effort)
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
                skin_services.restore_originals(obj)
                self.report({'INFO'}, "%s: original weights restored" % obj.name)
            else:
                skin_services.show_decoded(obj)
                self.report({'INFO'}, "%s: showing decoded weights" % obj.name)
        except (gather.GatherError, native.SkinpackError, preview.PreviewError) as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            progress.end()
        mesh.update()
        return {'FINISHED'}


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
        options = _all_influences_options()
        options["export_format"] = 'GLTF_SEPARATE' if filepath.lower().endswith(".gltf") else 'GLB'
        try:
            export.enabled, export.mode = True, self.mode
            for o, _ in saved_selection:
                o.select_set(o == obj or o == armature)
            bpy.ops.export_scene.gltf(filepath=filepath, use_selection=True, **options)
        except RuntimeError as error:
            problems = exporter.last_report.errors or [_exception_message(error)]
            self.report({'ERROR'}, "glTF export of %s failed: %s" % (obj.name, "; ".join(problems)))
            return {'CANCELLED'}
        finally:
            exporter.restore_previews()
            export.enabled, export.mode = saved_settings
            for o, selected in saved_selection:
                o.select_set(selected)
        report = exporter.last_report
        for warning in report.warnings():
            self.report({'WARNING'}, warning)
        if report.errors or not report.compressed:
            problems = "; ".join(report.errors) or "no skinned primitive found"
            self.report({'ERROR'}, "%s written without SKINPACK_packed_skin for some meshes: %s" % (filepath, problems))
            return {'CANCELLED'}
        self.report({'INFO'}, "%s: %s" % (filepath, report.summary()))
        return {'FINISHED'}


def _all_influences_options():
    """Every influence goes into the export (the library keeps the K strongest and says so):
    export_all_influences, which 3.4 to 5.x have (4.0+ also has export_influence_nb, ignored
    when all influences are exported)."""
    properties = bpy.ops.export_scene.gltf.get_rna_type().properties
    return {"export_all_influences": True} if "export_all_influences" in properties else {}


def _exception_message(error):
    """The exception line of an operator's RuntimeError (not the traceback's 'Location:' line)."""
    lines = [line.strip() for line in str(error).splitlines()]
    lines = [line for line in lines if line and not line.startswith(("Location:", "File ", "Traceback"))]
    return lines[-1] if lines else "unknown error"


classes = (SKINPACK_OT_compress, SKINPACK_OT_preview_error, SKINPACK_OT_preview_meshlets,
           SKINPACK_OT_clear_preview, SKINPACK_OT_toggle_decoded, SKINPACK_OT_export_gltf)


register, unregister = bpy.utils.register_classes_factory(classes)
