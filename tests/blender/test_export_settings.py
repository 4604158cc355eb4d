"""The user's data and files stay the user's, under every export setting that bit before:

- previews (Weight Error, meshlets) and Clear leave the active and render colour exactly as they
  were, on a mesh with two colour attributes of its own;
- opt-in: with the add-on enabled and nothing asked, Blender's export is byte-identical to an
  export without the add-on;
- colour export with everything on (3.4's export_colors + export_attributes: the same output as
  4.2+'s all colour attributes): the user's colours are written unchanged, the preview never,
  and the mesh is as before afterwards;
- Draco on (the exporter sees it on) with Skinpack on: refused loudly in both modes, nothing
  written (the one-click export never turns Draco on);
- Apply Modifiers with a modifier before the Armature: compressed from plain copies, the
  extension matches the exported vertices;
- a Compact export that cannot compress fails (operator and File > Export), writing nothing, and
  says why by object name (operator report; with 4.2+'s export log: an error popup, and
  is_critical set); a single-bone mesh reports no meaningless ratio.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import addon_utils  # noqa: E402
import bpy  # noqa: E402
import numpy as np  # noqa: E402

EXTENSION = "SKINPACK_packed_skin"
USER_COLORS = {"paint_a": (0.8, 0.1, 0.1, 1.0), "paint_b": (0.1, 0.2, 0.9, 1.0)}


def add_user_colors(obj):
    """Two colour attributes of the user's: paint_a renders (COLOR_0), paint_b is being painted."""
    mesh = obj.data
    for name, color in USER_COLORS.items():
        attribute = mesh.color_attributes.new(name, 'FLOAT_COLOR', 'POINT')
        attribute.data.foreach_set("color", np.tile(np.array(color, dtype=np.float32), len(mesh.vertices)))
    mesh.color_attributes.render_color_index = [a.name for a in mesh.color_attributes].index("paint_a")
    mesh.color_attributes.active_color_index = [a.name for a in mesh.color_attributes].index("paint_b")


def color_state(mesh):
    colors = mesh.color_attributes
    names = [a.name for a in colors]
    return names, colors.active_color_index, colors.render_color_index


def user_color_state(mesh):
    """Names of the active and render colour, and every user attribute's values."""
    colors = mesh.color_attributes
    values = {}
    for name in USER_COLORS:
        data = np.empty(len(mesh.vertices) * 4, dtype=np.float32)
        colors[name].data.foreach_get("color", data)
        values[name] = data.tobytes()
    return colors[colors.active_color_index].name, colors[colors.render_color_index].name, values


def check_previews_restore_colors(obj):
    mesh = obj.data
    before = color_state(mesh)
    for operator, kwargs in ((bpy.ops.skinpack.preview_error, {"mode": 'WEIGHT'}),
                             (bpy.ops.skinpack.preview_error, {"mode": 'POSE'}),
                             (bpy.ops.skinpack.preview_meshlets, {"mode": 'MESHLET'})):
        common.check(operator(**kwargs) == {'FINISHED'}, "preview %s" % kwargs)
        colors = mesh.color_attributes
        common.check(colors[colors.render_color_index].name == "paint_a",
                     "a preview took the render colour (what glTF writes as COLOR_0)")
        common.check(bpy.ops.skinpack.clear_preview() == {'FINISHED'}, "clear")
        common.check(color_state(mesh) == before, "after %s and Clear: %s, before %s"
                     % (kwargs, color_state(mesh), before))
    # Two previews in a row, then Clear: still exactly what was there.
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    bpy.ops.skinpack.preview_meshlets(mode='JOINTS')
    bpy.ops.skinpack.clear_preview()
    common.check(color_state(mesh) == before, "after two previews and Clear: %s" % (color_state(mesh),))


def export(path, obj, **settings):
    common.make_active(obj)
    obj.find_armature().select_set(True)
    bpy.ops.export_scene.gltf(filepath=path, export_format='GLB', use_selection=True, **settings)
    return path


def check_opt_in(args, obj):
    """Enabled and not asked: the file is exactly what Blender writes without the add-on."""
    common.check(not bpy.context.scene.skinpack_export.enabled, "Skinpack export on by default")
    with_addon = export(os.path.join(args.out, "opt_in_with_addon.glb"), obj)
    addon_utils.disable("skinpack", default_set=True)
    try:
        without = export(os.path.join(args.out, "opt_in_without_addon.glb"), obj)
    finally:
        addon_utils.enable("skinpack", default_set=True, handle_error=common._raise)
    with open(with_addon, "rb") as a, open(without, "rb") as b:
        common.check(a.read() == b.read(), "an export nobody asked Skinpack for differs from Blender's own")


def check_color_export(args, obj):
    """Everything exported: the user's two colours as they are, the preview nowhere."""
    mesh = obj.data
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    state = color_state(mesh), user_color_state(mesh)
    for enabled in (False, True):
        bpy.context.scene.skinpack_export.enabled = enabled
        path = export(os.path.join(args.out, "colors_%s.glb" % ("packed" if enabled else "plain")), obj,
                      export_colors=True, export_attributes=True)
        glb = common.Glb(path)
        for _, _, primitive in glb.skinned_primitives():
            attributes = primitive["attributes"]
            common.check(not any("SKINPACK" in key for key in attributes), "preview exported: %s" % sorted(attributes))
            common.check("_PAINT_B" in attributes and "COLOR_0" in attributes and "COLOR_1" not in attributes,
                         "user colours not exported as Blender does: %s" % sorted(attributes))
            color_0 = glb.accessor(attributes["COLOR_0"])
            common.check(np.allclose(color_0, USER_COLORS["paint_a"], atol=1e-3),
                         "COLOR_0 is not the user's render colour: %s" % color_0[:2])
            common.check((EXTENSION in primitive.get("extensions", {})) == enabled,
                         "extension when enabled=%s" % enabled)
        common.check((color_state(mesh), user_color_state(mesh)) == state, "the export changed the mesh's colours")
        common.check(mesh.color_attributes.get("skinpack_error") is not None, "the preview did not come back")
    bpy.context.scene.skinpack_export.enabled = False
    bpy.ops.skinpack.clear_preview()


def expect_refusal(call, path, *fragments):
    if os.path.exists(path):
        os.remove(path)
    # Blender 3.4's glTF exporter reports an exception raised in a pre-export hook with its
    # traceback; the refusal text must still be in it.
    message = common.refusal(call, *fragments, traceback_allowed=True)
    common.check(not os.path.exists(path), "%s was written although the export was refused" % path)
    return message


def check_draco(args, obj):
    """The exporter believes Draco is there (Debian's Blender has no Draco library)."""
    from io_scene_gltf2.io.com import gltf2_io_draco_compression_extension as draco
    available = draco.dll_exists
    draco.dll_exists = lambda *a, **k: True
    try:
        for mode in ('FALLBACK', 'COMPACT'):
            path = os.path.join(args.out, "draco_%s.glb" % mode.lower())
            settings = bpy.context.scene.skinpack_export
            settings.enabled, settings.mode = True, mode
            expect_refusal(lambda: export(path, obj, export_draco_mesh_compression_enable=True), path,
                           "Draco reorders vertices: turn off Draco or Skinpack")
    finally:
        draco.dll_exists = available
        bpy.context.scene.skinpack_export.enabled = False
        bpy.context.scene.skinpack_export.mode = 'FALLBACK'


def check_apply_modifiers(args, obj):
    """A Displace before the Armature: export_apply hands the hook a temporary mesh."""
    modifier = obj.modifiers.new("Displace", 'DISPLACE')
    modifier.strength = 0.05
    while obj.modifiers[0] != modifier:
        bpy.ops.object.modifier_move_up({"object": obj}, modifier=modifier.name)
    settings = bpy.context.scene.skinpack_export
    settings.enabled, settings.mode = True, 'COMPACT'
    try:
        path = export(os.path.join(args.out, "apply_modifiers.glb"), obj, export_apply=True)
    finally:
        settings.enabled, settings.mode = False, 'FALLBACK'
        obj.modifiers.remove(modifier)
    from skinpack.blender.exp import gltf2_skinpack_export as exporter
    common.check(not exporter.last_report.errors, "errors: %s" % exporter.last_report.errors)
    common.check([name for name, _ in exporter.last_report.compressed] == [obj.name],
                 "report does not name %s: %s" % (obj.name, exporter.last_report.compressed))
    glb = common.Glb(path)
    for _, _, primitive in glb.skinned_primitives():
        extension = primitive["extensions"][EXTENSION]
        positions = glb.json["accessors"][primitive["attributes"]["POSITION"]]["count"]
        common.check(glb.json["accessors"][extension["vertices"]]["count"] == positions,
                     "packed vertices do not match the exported ones")


class FakeLog:
    """Blender 4.2+'s export_settings['log'] (error/warning/info with popup=)."""

    def __init__(self):
        self.entries = []
        self.extension = None
        self.remove = lambda: None

    def error(self, text, popup=False):
        self.entries.append(("error", text, popup))

    def warning(self, text, popup=False):
        self.entries.append(("warning", text, popup))

    def info(self, text, popup=False):
        self.entries.append(("info", text, popup))


def with_log_4_2():
    """Gives the next exports a 4.2-style log: the pre-export callback is wrapped to put one
    into export_settings, as 4.2+ exporters do before any hook runs."""
    from skinpack.blender.exp import gltf2_skinpack_export as exporter
    log, original = FakeLog(), exporter.pre_export

    def pre_export(export_settings):
        export_settings["log"] = log
        log.extension = exporter._our_extension(export_settings)
        original(export_settings)

    exporter.pre_export = pre_export
    log.remove = lambda: setattr(exporter, "pre_export", original)
    return log


def check_failed_compact(args, obj):
    """A budget the library refuses: Compact fails and writes nothing, Fallback warns."""
    mesh_settings = obj.data.skinpack
    mesh_settings.budget, mesh_settings.custom_bits = 'CUSTOM', 2
    try:
        path = os.path.join(args.out, "failed_compact.glb")
        common.make_active(obj)
        message = expect_refusal(lambda: bpy.ops.skinpack.export_gltf(filepath=path, mode='COMPACT'), path,
                                 obj.name, "bits per vertex")
        common.check("Location:" not in message.splitlines()[-1], "the report hides the error: %s" % message)
        settings = bpy.context.scene.skinpack_export
        settings.enabled, settings.mode = True, 'COMPACT'
        log = with_log_4_2()
        try:
            expect_refusal(lambda: export(path, obj), path, "Compact export not written", obj.name)
        finally:
            settings.enabled, settings.mode = False, 'FALLBACK'
            log.remove()
        common.check(any(level == "error" and popup and obj.name in text for level, text, popup in log.entries),
                     "no error popup naming %s in the exporter's log: %s" % (obj.name, log.entries))
        common.check(log.extension is not None and log.extension.is_critical, "is_critical not set")
        fallback = os.path.join(args.out, "failed_fallback.glb")
        common.make_active(obj)
        common.refusal(lambda: bpy.ops.skinpack.export_gltf(filepath=fallback, mode='FALLBACK'),
                       obj.name, "without SKINPACK_packed_skin")  # compressed nothing: not a success
        common.check(os.path.exists(fallback), "fallback file (valid, uncompressed) not written")
    finally:
        mesh_settings.budget = '32'


def check_lost_fallback_buffer(args, obj):
    """The hook that adds the compact fallback buffer fails (the 3.4 exporter swallows hook
    exceptions): the export is refused, naming the object, instead of writing JOINTS_0/WEIGHTS_0
    without a bufferView (read as zeros by loaders without the extension)."""
    from skinpack.blender.exp import gltf2_skinpack_export as exporter
    original = exporter.add_fallback_buffer

    def broken(gltf, placeholders):
        raise RuntimeError("test: fallback buffer hook broken")

    settings = bpy.context.scene.skinpack_export
    settings.enabled, settings.mode = True, 'COMPACT'
    exporter.add_fallback_buffer = broken
    try:
        path = os.path.join(args.out, "lost_fallback_buffer.glb")
        expect_refusal(lambda: export(path, obj), path, "Compact export not written", obj.name, "fallback buffer")
    finally:
        exporter.add_fallback_buffer = original
        settings.enabled, settings.mode = False, 'FALLBACK'


def check_exporter_failure(args, obj):
    """The exporter itself fails between the callbacks: the preview comes back (operator at once,
    File > Export at the UI's next idle moment through a timer) and the mesh is as before."""
    from io_scene_gltf2.blender.exp import gltf2_blender_export
    from skinpack.blender.exp import gltf2_skinpack_export as exporter
    mesh = obj.data
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    state = color_state(mesh), user_color_state(mesh)
    original = gltf2_blender_export.__dict__["__export"]

    def failing_export(export_settings):
        raise RuntimeError("exporter failure for the test")

    gltf2_blender_export.__dict__["__export"] = failing_export
    try:
        path = os.path.join(args.out, "exporter_failure.glb")
        common.make_active(obj)
        expect_refusal(lambda: bpy.ops.skinpack.export_gltf(filepath=path, mode='FALLBACK'), path,
                       "exporter failure for the test")
        common.check((color_state(mesh), user_color_state(mesh)) == state, "operator: preview not restored")
        expect_refusal(lambda: export(path, obj), path, "exporter failure for the test")
        common.check(mesh.color_attributes.get("skinpack_error") is None, "the preview was exported")
        common.check(bpy.app.timers.is_registered(exporter._restore_after_failure), "no restore timer")
        exporter._restore_after_failure()  # what the timer does once the UI is idle again
        common.check((color_state(mesh), user_color_state(mesh)) == state, "timer: preview not restored")
    finally:
        gltf2_blender_export.__dict__["__export"] = original
        if bpy.app.timers.is_registered(exporter._restore_after_failure):
            bpy.app.timers.unregister(exporter._restore_after_failure)
    bpy.ops.skinpack.clear_preview()


def check_single_bone_message(obj):
    from skinpack import skin_services
    from skinpack.io import storage
    single = obj.copy()
    single.data = obj.data.copy()
    single.name = "SingleBone"
    bpy.context.scene.collection.objects.link(single)
    keep = single.vertex_groups[0]
    for group in list(single.vertex_groups):
        if group != keep:
            single.vertex_groups.remove(group)
    keep.add(list(range(len(single.data.vertices))), 1.0, 'REPLACE')
    common.make_active(single)
    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "single-bone compress")
    line = skin_services.stats_line(storage.load_result(single.data).stats)
    common.check("x)" not in line and "one joint tuple" in line, "single-bone stats line: %s" % line)
    bpy.data.objects.remove(single)


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    add_user_colors(obj)
    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "compress")
    check_previews_restore_colors(obj)
    check_opt_in(args, obj)
    check_color_export(args, obj)
    check_draco(args, obj)
    check_apply_modifiers(args, obj)
    check_failed_compact(args, obj)
    check_lost_fallback_buffer(args, obj)
    check_exporter_failure(args, obj)
    check_single_bone_message(obj)


common.run(main)
