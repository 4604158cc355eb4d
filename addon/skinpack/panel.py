"""The "Skinpack" panel in Properties > Object Data of a mesh deformed by an armature."""

import bpy

from . import gather, meshlet_preview, preview, properties, skin_services
from .blender.exp import gltf2_skinpack_export as exporter
from .io import native, storage


class SKINPACK_PT_skin(bpy.types.Panel):
    bl_label = "Skinpack"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "data"
    # Open from the start (it used to start collapsed). It still comes after Blender's own Object
    # Data panels: bl_order cannot go below their 0, and equal orders keep registration order.

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.type == 'MESH' and gather.find_armature(obj) is not None

    def draw(self, context):
        layout = self.layout
        obj = context.object
        mesh = obj.data
        if native.load() is None:
            box = layout.box()
            box.label(text="Skinpack's native library could not be loaded.", icon='ERROR')
            for line in _wrap(native.load_error(), 60):
                box.label(text=line)
            box.label(text="Reinstall the add-on zip built by ./build.sh for this platform.")
            return

        settings = mesh.skinpack
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(settings, "method")
        layout.prop(settings, "budget")
        if settings.budget == 'CUSTOM':
            layout.prop(settings, "custom_bits")
        elif settings.budget == 'ERROR':
            layout.prop(settings, "max_error")
        layout.prop(settings, "max_influences")

        deform_count, ignored = gather.group_summary(obj)
        armature = gather.find_armature(obj)
        layout.label(text="%d deform groups of %s" % (deform_count, armature.name), icon='ARMATURE_DATA')
        if ignored:
            layout.label(text="%d other vertex groups ignored (not deform bones)" % len(ignored), icon='INFO')

        row = layout.row()
        row.scale_y = 1.4
        row.enabled = not storage.showing_decoded(mesh)
        row.operator("skinpack.compress", icon='MOD_DATA_TRANSFER')

        result = storage.load_result(mesh)
        if result is not None:
            _draw_stats(layout, mesh, result)
            _draw_preview(layout, context, mesh)
            col = layout.column(align=True)
            decoded = storage.showing_decoded(mesh)
            col.operator("skinpack.toggle_decoded", depress=decoded,
                         text="Showing Decoded Weights (B)" if decoded else "Show Decoded Weights (A/B)",
                         icon='ARROW_LEFTRIGHT')
            col.operator("skinpack.export_gltf", icon='EXPORT')
        elif storage.showing_decoded(mesh):
            layout.operator("skinpack.toggle_decoded", text="Restore Original Weights", icon='LOOP_BACK')
        _draw_last_export(layout)
        _draw_meshlets(layout, context, obj)


def _draw_last_export(layout):
    """What the latest glTF export of this session compressed, pruned and left out, by object
    name: Blender 3.x has no export log to show it, and the console is not where users look."""
    report = exporter.last_report
    if not report.compressed and not report.errors:
        return
    box = layout.box()
    box.label(text="Last glTF export: " + report.summary(), icon='EXPORT')
    for warning in report.warnings():
        for line in _wrap(warning, 70):
            box.label(text=line, icon='INFO')
    for error in report.errors:
        for line in _wrap(error, 70):
            box.label(text=line, icon='ERROR')


def _draw_stats(layout, mesh, result):
    stats = result.stats
    box = layout.box()
    if storage.is_stale(mesh, result):
        box.label(text="Stored result is out of date: compress again", icon='ERROR')
    grid = box.grid_flow(row_major=True, columns=2, even_columns=True, align=True)
    per_vertex_data = skin_services.stores_per_vertex_data(stats)
    rows = (
        ("Method", "%s, K = %d" % (stats["method"].upper(), stats["influences"])),
        ("Bits / vertex", "%.1f \u2192 %.1f" % (stats["input_bits_per_vertex"], stats["bits_per_vertex"])
         if per_vertex_data else "%.1f \u2192 0 (one joint tuple)" % stats["input_bits_per_vertex"]),
        ("Ratio", "%.1f : 1" % stats["ratio"] if per_vertex_data else "only the tuple table is stored"),
        ("Unique joint tuples", "%d" % stats["unique_tuples"]),
        ("Tuple / weight bits", "%d + %d" % (stats["tuple_bits"], stats["weight_bits"])),
        ("Max weight error", "%.2e" % stats["max_error"]),
        ("RMS weight error", "%.2e" % stats["rms_error"]),
        ("Pruned vertices", "%d (max %.3f)" % (stats["pruned_vertices"], stats["max_pruning_error"])),
    )
    for label, value in rows:
        grid.label(text=label)
        grid.label(text=value)
    pruning = skin_services.pruning_text(stats)
    if pruning:
        box.label(text=pruning, icon='INFO')


def _draw_ramp(box, context, scale, number_format):
    """The heat-map colour ramp as swatches, each with its value right under it (same columns)."""
    legend = context.window_manager.skinpack_legend
    grid = box.grid_flow(row_major=True, columns=len(preview.RAMP), even_columns=True, align=True)
    for index in range(len(preview.RAMP)):
        grid.prop(legend, "color_%d" % index, text="")
    for label in preview.ramp_ticks(scale, number_format):
        grid.label(text=label)


def _draw_preview(layout, context, mesh):
    row = layout.row(align=True)
    row.operator("skinpack.preview_error", text="Weight Error", icon='GROUP_VCOL').mode = 'WEIGHT'
    row.operator("skinpack.preview_error", text="Pose Error", icon='POSE_HLT').mode = 'POSE'
    row.operator("skinpack.clear_preview", text="", icon='X')
    shown = preview.legend(mesh)
    if shown is None:
        return
    label, minimum, maximum, scale = shown
    box = layout.box()
    box.label(text=label)
    _draw_ramp(box, context, scale, "%.2e")
    box.label(text="Values %.2e \u2026 %.2e" % (minimum, maximum))


def _draw_meshlets(layout, context, obj):
    """The "Meshlets" box: builder and limits, the two preview modes, the library's stats."""
    settings = obj.skinpack_meshlets
    box = layout.box()
    box.label(text="Meshlets", icon='MESH_ICOSPHERE')
    box.prop(settings, "builder")
    col = box.column(align=True)
    col.prop(settings, "max_vertices")
    col.prop(settings, "max_triangles")
    col.prop(settings, "palette_size")
    col.prop(settings, "palette_effort")
    row = box.row(align=True)
    for mode, text, icon in (('MESHLET', "Meshlets", 'MESH_ICOSPHERE'), ('JOINTS', "Joints", 'BONE_DATA')):
        op = row.operator("skinpack.preview_meshlets", text=text, icon=icon)
        op.mode = mode
        op.builder = settings.builder
        op.max_vertices = settings.max_vertices
        op.max_triangles = settings.max_triangles
        op.palette_size = settings.palette_size
        op.palette_effort = settings.palette_effort
    row.operator("skinpack.clear_preview", text="", icon='X')
    mode = meshlet_preview.shown_mode(obj.data)
    if mode is None or not settings.valid:
        return
    builder_names = {key: name for key, name, _ in properties.MESHLET_BUILDER_ITEMS}
    builder = builder_names.get(settings.shown_builder, settings.shown_builder)
    grid = box.grid_flow(row_major=True, columns=2, even_columns=True, align=True)
    rows = (
        ("Builder", builder),
        ("Meshlets", "%d" % settings.meshlet_count),
        ("Mean vertices", "%.1f" % settings.mean_vertices),
        ("Mean triangles", "%.1f" % settings.mean_triangles),
        ("Joints / meshlet", "%.1f mean, %d max" % (settings.mean_joints, settings.max_joints)),
        ("Tuple index bits", "%d global → %.2f local (max %d)" % (
            settings.global_tuple_bits, settings.local_tuple_bits_mean, settings.local_tuple_bits_max)),
    )
    for label, value in rows:
        grid.label(text=label)
        grid.label(text=value)
    if mode == 'JOINTS':
        # Same ramp as the error heat map, 0 to the palette size the preview was built with.
        scale = obj.data[storage.PREVIEW_KEY].get("scale", 0.0)
        box.label(text="Joints per meshlet")
        _draw_ramp(box, context, scale, "%g")
    else:
        box.label(text="One colour per meshlet (a face shows its first triangle's)")


def _wrap(text, width):
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = (line + " " + word).strip()
    return lines + ([line] if line else [])


class SKINPACK_PT_skin_sidebar(SKINPACK_PT_skin):
    """The same panel in the 3D viewport's sidebar (N), Skinpack tab: where the artist works,
    since in Object Data it can only come after Blender's own panels."""
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Skinpack"
    bl_context = "objectmode"


classes = (SKINPACK_PT_skin, SKINPACK_PT_skin_sidebar)


register, unregister = bpy.utils.register_classes_factory(classes)
