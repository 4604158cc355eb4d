"""Install from the built zip, enable/disable/re-enable without residue, and a clear message
(not a traceback) when the native library cannot be loaded."""

import os
import subprocess
import sys
import zipfile

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import addon_utils  # noqa: E402
import bpy  # noqa: E402

OPERATORS = ("compress", "preview_error", "clear_preview", "toggle_decoded", "export_gltf", "preview_meshlets")
TYPES = ("SKINPACK_OT_compress", "SKINPACK_OT_preview_error", "SKINPACK_OT_clear_preview",
         "SKINPACK_OT_toggle_decoded", "SKINPACK_OT_export_gltf", "SKINPACK_OT_preview_meshlets", "SKINPACK_PT_skin",
         "SKINPACK_PT_skin_sidebar")
CLASSES = []  # every class the add-on registers, collected while it is enabled


def registered_names():
    present = [name for name in TYPES if hasattr(bpy.types, name)]
    present += [cls.__name__ for cls in CLASSES if cls.is_registered]
    present += ["Mesh.skinpack"] if hasattr(bpy.types.Mesh, "skinpack") else []
    present += ["Scene.skinpack_export"] if hasattr(bpy.types.Scene, "skinpack_export") else []
    present += ["WindowManager.skinpack_legend"] if hasattr(bpy.types.WindowManager, "skinpack_legend") else []
    present += ["Object.skinpack_meshlets"] if hasattr(bpy.types.Object, "skinpack_meshlets") else []
    menu = bpy.types.TOPBAR_MT_file_export
    draw_funcs = getattr(menu.draw, "_draw_funcs", [])
    present += ["export menu"] if any(getattr(f, "__module__", "").startswith("skinpack") for f in draw_funcs) else []
    return present


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack import operators, panel, properties
    from skinpack.io import storage
    CLASSES.extend(properties.classes + operators.classes + panel.classes)
    common.check(set(registered_names()) >= set(TYPES) | {c.__name__ for c in CLASSES},
                 "not registered: %s" % registered_names())
    for name in OPERATORS:
        common.check(hasattr(bpy.ops.skinpack, name), "missing operator skinpack.%s" % name)

    # Three cycles: every disable leaves nothing behind, every enable works again.
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")

    # The settings start at the library's defaults (asked at load, not copied into Python).
    from skinpack.io import native
    library, meshlets = native.default_options(), native.meshlet_options()
    settings, meshlet_settings = obj.data.skinpack, obj.skinpack_meshlets
    common.check((settings.method.lower(), settings.max_influences, settings.budget)
                 == (native.METHODS[library.method], library.max_influences, str(library.vertex_bits))
                 and (meshlet_settings.builder.lower(), meshlet_settings.max_vertices, meshlet_settings.max_triangles,
                      meshlet_settings.palette_size)
                 == (native.MESHLET_BUILDERS[meshlets.builder], meshlets.max_vertices, meshlets.max_triangles,
                     meshlets.max_joints),
                 "settings do not start at the library's defaults")
    for cycle in range(3):
        addon_utils.disable("skinpack", default_set=True)
        common.check(registered_names() == [], "cycle %d: residue after disable: %s" % (cycle, registered_names()))
        common.check("skinpack" not in bpy.context.preferences.addons, "still listed as enabled")
        addon_utils.enable("skinpack", default_set=True, handle_error=common._raise)
        common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "compress after re-enable")
    texts = common.draw_skinpack_panel(obj)
    common.check(any(t.startswith("operator:skinpack.compress") for t in texts), "panel without Compress: %s" % texts)
    common.check(any("Ratio" == t for t in texts), "panel without stats: %s" % texts)
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    texts = common.draw_skinpack_panel(obj)
    common.check(any(t.startswith("Weight error") for t in texts) and any(t.startswith("Values ") for t in texts),
                 "panel without heat-map legend: %s" % texts)
    # One tick per swatch, in the swatches' columns: 0, scale/4, ..., >= scale (red labelled).
    from skinpack import preview
    scale = obj.data[storage.PREVIEW_KEY]["scale"]
    ticks = preview.ramp_ticks(scale, "%.2e")
    common.check(len(ticks) == len(preview.RAMP) and ticks[0] == "0" and ticks[-1] == "\u2265 %.2e" % scale
                 and ticks[2] == "%.2e" % (scale / 2), "legend ticks %s for scale %g" % (ticks, scale))
    common.check(any(texts[at:at + len(ticks)] == ticks for at in range(len(texts))),
                 "panel legend ticks %s not in %s" % (ticks, texts))

    # The glTF exporter's hooks are found on the top-level module.
    module = sys.modules["skinpack"]
    for name in ("glTF2ExportUserExtension", "glTF2ImportUserExtension", "register_panel",
                 "glTF2_pre_export_callback", "glTF2_post_export_callback"):
        common.check(hasattr(module, name), "skinpack.%s missing (the glTF add-on looks it up)" % name)
    unregister = module.register_panel()
    common.check(hasattr(bpy.types, "SKINPACK_PT_gltf_export"), "exporter panel not registered")
    module.register_panel()  # the exporter calls it on every invoke
    texts = []
    module.blender.exp.gltf2_skinpack_export.draw_settings(common.RecordingLayout(texts), bpy.context)
    common.check(any("Skinpack panel" in t for t in texts), "exporter section draws nothing useful: %s" % texts)
    unregister()
    common.check(not hasattr(bpy.types, "SKINPACK_PT_gltf_export"), "exporter panel left registered")
    module.register_panel()
    addon_utils.disable("skinpack", default_set=True)
    common.check(not hasattr(bpy.types, "SKINPACK_PT_gltf_export"), "exporter panel survives disable")

    # A zip without the library, in a fresh Blender (this process still has the library mapped).
    broken_zip = os.path.join(args.out, "skinpack_without_library.zip")
    with zipfile.ZipFile(args.zip) as source, zipfile.ZipFile(broken_zip, "w") as target:
        for item in source.infolist():
            if not item.filename.endswith(".so"):
                target.writestr(item, source.read(item.filename))
    environment = dict(os.environ, BLENDER_USER_SCRIPTS=os.path.join(args.out, "broken", "scripts"),
                       BLENDER_USER_CONFIG=os.path.join(args.out, "broken", "config"),
                       BLENDER_USER_DATAFILES=os.path.join(args.out, "broken", "datafiles"))
    child = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                            "--python", __file__, "--", "--zip", broken_zip, "--shared", args.shared,
                            "--out", args.out, "--broken-library"],
                           env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(child.stdout[-3000:])
    common.check(child.returncode == 0 and "BROKEN LIBRARY CHECKS PASSED" in child.stdout,
                 "the add-on without its library misbehaved (exit %d)" % child.returncode)


def broken_library_main():
    args = common.arguments()
    common.install_addon(args.zip)  # registers although the library is missing
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    texts = common.draw_skinpack_panel(obj)
    common.check(any("could not be loaded" in t for t in texts), "no load message in panel: %s" % texts)
    common.check(any("libskinpack.so" in t for t in texts), "message does not name the library: %s" % texts)
    before = common.weight_snapshot(obj.data)
    common.refusal(bpy.ops.skinpack.compress, "Cannot load")
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "compress without library")
    print("BROKEN LIBRARY CHECKS PASSED")


if "--broken-library" in sys.argv:
    sys.argv.remove("--broken-library")
    common.run(broken_library_main)
else:
    common.run(main)
