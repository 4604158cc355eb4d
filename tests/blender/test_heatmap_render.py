"""A headless Workbench render of the heat map (weight and pose error on RE_Player) is a real
picture: the mesh covers a good part of the frame and shows several ramp colours, and the legend
under it has a swatch per ramp colour with its value; the pose error is in mm (metric scene)
at the frame shown. With --docs the pictures go to docs/images (the user guide's)."""

import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import skinpack_render as render  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402


def check_picture(path):
    pixels = render.image_pixels(path)[:, :, :3]
    flat = pixels.reshape(-1, 3)
    background = np.median(np.concatenate([flat[:50], flat[-50:]]), axis=0)
    covered = np.abs(flat - background).max(axis=1) > 0.05
    quantised = np.unique((flat[covered] * 16).astype(np.int32), axis=0)
    print("%s: %.1f%% covered, %d colours, std %.3f" % (os.path.basename(path), 100 * covered.mean(),
                                                         len(quantised), flat.std()))
    common.check(covered.mean() > 0.05, "%s: the mesh covers %.1f%% of the frame" % (path, 100 * covered.mean()))
    common.check(len(quantised) > 20, "%s: only %d colours: a flat image" % (path, len(quantised)))
    hue_spread = np.ptp(flat[covered][:, 2] - flat[covered][:, 0])
    common.check(hue_spread > 0.3, "%s: blue-red spread %.2f: the heat map does not show" % (path, hue_spread))


def check_legend(path):
    """The legend under the mesh: one swatch per ramp colour where add_legend puts it, blue at
    the left to red at the right, all different, and text (light pixels) around them."""
    pixels = render.image_pixels(path)[::-1, :, :3]  # Blender's rows start at the bottom
    height, width = pixels.shape[:2]
    columns = len(render_colors())
    row = int(height * (1 - 0.075))
    samples = [pixels[row, int(width / 2 + (index - (columns - 1) / 2) * width * 0.92 / columns)]
               for index in range(columns)]
    common.check(samples[0][2] > samples[0][0] and samples[-1][0] > samples[-1][2],
                 "%s: legend swatches do not run from blue to red: %s" % (path, samples))
    common.check(all(np.abs(a - b).max() > 0.05 for i, a in enumerate(samples) for b in samples[i + 1:]),
                 "%s: legend swatches are not distinct: %s" % (path, samples))
    band = pixels[int(height * (1 - render.LEGEND_BAND)):]
    common.check((band.min(axis=2) > 0.5).sum() > 200, "%s: no legend text" % path)


def render_colors():
    from skinpack import preview
    return preview.RAMP


def check_pose_units(obj):
    """The pose error is shown in mm in a metric scene (Unit Scale applied), with the frame."""
    from skinpack import preview
    from skinpack.io import storage
    scene = bpy.context.scene
    scene.unit_settings.system = 'NONE'
    bpy.ops.skinpack.preview_error(mode='POSE')
    plain = obj.data[storage.PREVIEW_KEY]["maximum"]
    scene.unit_settings.system, scene.unit_settings.scale_length = 'METRIC', 1.0
    bpy.ops.skinpack.preview_error(mode='POSE')
    info = obj.data[storage.PREVIEW_KEY]
    label = preview.mode_label(info)
    common.check(abs(info["maximum"] - plain * 1000) <= 1e-3 * info["maximum"], "mm: %g vs %g scene units"
                 % (info["maximum"], plain))
    common.check("(mm)" in label and "frame %d" % scene.frame_current in label, "pose legend %r" % label)


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    bpy.ops.skinpack.compress()
    pictures = []
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    pictures.append(render.render_workbench(os.path.join(args.out, "heatmap_weight.png"), obj,
                                            legend=render.heat_map_legend(obj)))
    armature = obj.find_armature()
    for bone in armature.pose.bones:
        bone.rotation_mode = 'XYZ'
    for name, degrees in (("upper_arm.L", (0, 0, 40)), ("upper_arm.R", (0, 0, -40)), ("thigh.L", (25, 0, 0)),
                          ("forearm.L", (0, 0, 30)), ("spine.003", (10, 0, 0))):
        bone = armature.pose.bones.get(name) or armature.pose.bones.get("DEF-" + name)
        if bone is not None:
            bone.rotation_euler = tuple(render.angle(d) for d in degrees)
    bpy.context.view_layer.update()
    check_pose_units(obj)
    pictures.append(render.render_workbench(os.path.join(args.out, "heatmap_pose.png"), obj,
                                            legend=render.heat_map_legend(obj)))
    for path in pictures:
        check_picture(path)
        check_legend(path)
        if args.docs:
            os.makedirs(args.docs, exist_ok=True)
            shutil.copy(path, os.path.join(args.docs, os.path.basename(path)))


common.run(main)
