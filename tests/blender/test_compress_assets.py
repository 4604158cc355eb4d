"""Compress the shared assets: stats are sane and honour the budget, the heat maps carry the
library's numbers, the result survives save/reload, nothing touches the weights.
(Undo: test_undo.py.)"""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402

ASSETS = (("RE_Player_female.blend", ["RE_Player"]),
          ("RobotExpressive.blend", ["Hand.L", "Hand.R"]),
          ("skinned_cylinder.blend", ["Cylinder"]))


def pose_armature(armature):
    """A visible pose: every deform bone bent a little (deterministic)."""
    for index, bone in enumerate(armature.pose.bones):
        bone.rotation_mode = 'XYZ'
        bone.rotation_euler = (math.radians(12 + index % 7), math.radians(-8 + index % 5), math.radians(5))
    bpy.context.view_layer.update()


def check_stats(name, stats, budget_bits):
    common.check(stats["ratio"] > 1.0, "%s: ratio %.2f" % (name, stats["ratio"]))
    common.check(stats["max_error"] <= stats["error_bound"] + 1e-6,
                 "%s: max error %g above the bound %g" % (name, stats["max_error"], stats["error_bound"]))
    common.check(0 <= stats["rms_error"] <= stats["max_error"], "%s: RMS %g" % (name, stats["rms_error"]))
    common.check(stats["unique_tuples"] >= 1 and stats["tuple_bits"] == (stats["unique_tuples"] - 1).bit_length(),
                 "%s: %d tuples in %d bits" % (name, stats["unique_tuples"], stats["tuple_bits"]))
    if budget_bits:
        common.check(stats["tuple_bits"] + stats["weight_bits"] <= budget_bits,
                     "%s: %d + %d bits over the %d-bit budget" % (name, stats["tuple_bits"], stats["weight_bits"],
                                                              budget_bits))
    common.check(abs(stats["bits_per_vertex"] - stats["tuple_bits"] - stats["weight_bits"]
                     - stats["lut_bits_per_vertex"]) < 1e-6, "%s: bits per vertex do not add up" % name)


def check_heat_map(obj, result):
    """The colour attribute is the ramp applied to the library's per-vertex errors, and those
    equal what the library reports for the same weights right now."""
    from skinpack import gather, preview, skin_services
    from skinpack.io import native
    skin = gather.gather(obj)
    options = skin_services.compression_options(obj.data.skinpack.options_summary())
    fresh = native.compress(skin.joints, skin.weights, len(skin.joint_names), options)
    common.check(np.array_equal(fresh.per_vertex_error, result.per_vertex_error),
                 "%s: stored per-vertex errors differ from the library's" % obj.name)
    common.check(np.array_equal(fresh.words, result.words) and np.array_equal(fresh.lut, result.lut),
                 "%s: stored words/LUT differ from a fresh compression" % obj.name)
    attribute = obj.data.color_attributes[preview.ATTRIBUTE_NAME]
    colors = np.empty(len(attribute.data) * 4, dtype=np.float32)
    attribute.data.foreach_get("color", colors)
    expected = preview.heat_colors(result.per_vertex_error, result.stats["error_bound"])
    common.check(np.allclose(colors.reshape(-1, 4), expected, atol=1e-6), "%s: heat-map colours" % obj.name)
    common.check(obj.data.color_attributes.active_color_name == preview.ATTRIBUTE_NAME,
                 "%s: heat map is not the active colour attribute" % obj.name)


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack.io import storage

    for blend, names in ASSETS:
        for name in names:
            obj = common.open_asset(args, blend, name)
            before = common.weight_snapshot(obj.data)

            # Every method at the three presets and an error target.
            for method in ('FIXED', 'CUBE', 'POT', 'ANY', 'OSS'):
                for budget in ('32', '48', '64', 'ERROR'):
                    obj.data.skinpack.method, obj.data.skinpack.budget = method, budget
                    obj.data.skinpack.max_error = 0.002
                    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "%s %s %s" % (name, method, budget))
                    stats = storage.load_result(obj.data).stats
                    label = "%s %s/%s" % (name, method, budget)
                    check_stats(label, stats, 0 if budget == 'ERROR' else int(budget))
                    if budget == 'ERROR':
                        common.check(stats["error_bound"] <= 0.002, "%s: bound %g" % (label, stats["error_bound"]))
            common.assert_same_weights(before, common.weight_snapshot(obj.data), name + " after compress")

            # The default (OSS, 32 bits) again, then both previews.
            obj.data.skinpack.method, obj.data.skinpack.budget = 'OSS', '32'
            bpy.ops.skinpack.compress()
            result = storage.load_result(obj.data)
            print("%s: %s" % (name, result.stats))
            bpy.ops.skinpack.preview_error(mode='WEIGHT')
            check_heat_map(obj, result)
            common.check(bpy.context.scene.display.shading.color_type == 'VERTEX', "viewport not switched")
            pose_armature(obj.find_armature())
            bpy.ops.skinpack.preview_error(mode='POSE')
            legend = obj.data[storage.PREVIEW_KEY]
            common.check(legend["mode"] == 'POSE' and legend["minimum"] >= 0.0, "%s: pose legend" % name)
            if result.stats["max_error"] > 0:
                common.check(legend["maximum"] > 0.0, "%s: a posed mesh with weight errors shows no deformation "
                                                      "error" % name)
            common.assert_same_weights(before, common.weight_snapshot(obj.data), name + " after pose preview")
            bpy.ops.skinpack.clear_preview()
            common.check(obj.data.color_attributes.get("skinpack_error") is None, "clear left the attribute")
            common.check(storage.PREVIEW_KEY not in obj.data, "clear left the legend")

            # Save and reload: the stored result is identical.
            path = os.path.join(args.out, "%s.blend" % name)
            bpy.ops.wm.save_as_mainfile(filepath=path)
            bpy.ops.wm.open_mainfile(filepath=path)
            obj = bpy.data.objects[name]
            reloaded = storage.load_result(obj.data)
            common.check(reloaded is not None and reloaded.stats == result.stats
                         and np.array_equal(reloaded.words, result.words)
                         and np.array_equal(reloaded.lut, result.lut), "%s: result lost on reload" % name)
            common.assert_same_weights(before, common.weight_snapshot(obj.data), name + " after reload")



common.run(main)
