"""A headless Workbench render of the heat map (weight and pose error on RE_Player) is a real
picture: the mesh covers a good part of the frame and shows several ramp colours."""

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


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    bpy.ops.skinpack.compress()
    pictures = []
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    pictures.append(render.render_workbench(os.path.join(args.out, "heatmap_weight.png"), obj))
    armature = obj.find_armature()
    for bone in armature.pose.bones:
        bone.rotation_mode = 'XYZ'
    for name, degrees in (("upper_arm.L", (0, 0, 40)), ("upper_arm.R", (0, 0, -40)), ("thigh.L", (25, 0, 0)),
                          ("forearm.L", (0, 0, 30)), ("spine.003", (10, 0, 0))):
        bone = armature.pose.bones.get(name) or armature.pose.bones.get("DEF-" + name)
        if bone is not None:
            bone.rotation_euler = tuple(render.angle(d) for d in degrees)
    bpy.context.view_layer.update()
    bpy.ops.skinpack.preview_error(mode='POSE')
    pictures.append(render.render_workbench(os.path.join(args.out, "heatmap_pose.png"), obj))
    for path in pictures:
        check_picture(path)
        if args.docs:
            os.makedirs(args.docs, exist_ok=True)
            shutil.copy(path, os.path.join(args.docs, os.path.basename(path)))


common.run(main)
