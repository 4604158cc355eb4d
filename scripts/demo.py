"""Skinpack demo: a procedurally built, rigged and posed character, compressed in Blender.

Run by scripts/demo.sh (./build.sh demo), headless, no GPU, no input files:
  1. builds a character: a skeleton graph turned into a closed mesh (Skin + Subdivision
     modifiers), an armature on the same graph, automatic (bone heat) weights, a short animation;
  2. compresses its weights with the add-on (skinpack.compress, OSS, 32 bits a vertex);
  3. renders the weight-error and the pose-error heat maps with Workbench to PNGs;
  4. exports compressed glTF (fallback and compact) through Blender's exporter + the add-on's
     hook, validates them with the Khronos validator when tools/validate.mjs is set up, decodes
     one with `skinpack decompress` when the CLI is built;
  5. prints the stats table.
Arguments after `--`: --zip ADDON_ZIP --out DIR [--validator tools/validate.mjs] [--cli skinpack]
"""

import argparse
import json
import math
import os
import subprocess
import sys

import addon_utils
import bpy
import numpy

sys.path.insert(0, os.path.dirname(__file__))
import skinpack_render  # noqa: E402

if not hasattr(numpy, "bool"):  # Debian's Blender 3.4 glTF add-on with numpy >= 1.24
    numpy.bool = numpy.bool_

# The character's skeleton: joint positions (metres, Z up, facing -Y) and bones (parent, head, tail).
JOINTS = {
    "pelvis": (0, 0, 1.00), "spine": (0, 0, 1.25), "chest": (0, 0, 1.45), "neck": (0, 0, 1.58),
    "head": (0, 0, 1.75), "head_top": (0, 0, 1.92),
    "hip.L": (0.11, 0, 0.95), "knee.L": (0.12, -0.02, 0.52), "ankle.L": (0.12, 0, 0.08), "toe.L": (0.12, -0.15, 0.03),
    "shoulder.L": (0.20, 0, 1.47), "elbow.L": (0.46, 0.02, 1.45), "wrist.L": (0.70, 0, 1.44),
    "fingers.L": (0.80, 0, 1.44),
}
for name, (x, y, z) in list(JOINTS.items()):
    if name.endswith(".L"):
        JOINTS[name[:-2] + ".R"] = (-x, y, z)
BONES = [  # (bone, parent, head joint, tail joint)
    ("hips", None, "pelvis", "spine"), ("spine", "hips", "spine", "chest"), ("chest", "spine", "chest", "neck"),
    ("neck", "chest", "neck", "head"), ("head", "neck", "head", "head_top"),
]
for side in ("L", "R"):
    BONES += [
        ("thigh.%s" % side, "hips", "hip.%s" % side, "knee.%s" % side),
        ("shin.%s" % side, "thigh.%s" % side, "knee.%s" % side, "ankle.%s" % side),
        ("foot.%s" % side, "shin.%s" % side, "ankle.%s" % side, "toe.%s" % side),
        ("upper_arm.%s" % side, "chest", "shoulder.%s" % side, "elbow.%s" % side),
        ("forearm.%s" % side, "upper_arm.%s" % side, "elbow.%s" % side, "wrist.%s" % side),
        ("hand.%s" % side, "forearm.%s" % side, "wrist.%s" % side, "fingers.%s" % side),
    ]
# Mesh edges: the bones, plus pelvis-hip and chest-shoulder links.
EDGES = [(head, tail) for _, _, head, tail in BONES] + [("pelvis", "hip.L"), ("pelvis", "hip.R"),
                                                         ("chest", "shoulder.L"), ("chest", "shoulder.R")]
RADII = {"pelvis": 0.16, "spine": 0.14, "chest": 0.17, "neck": 0.06, "head": 0.11, "head_top": 0.09,
         "hip": 0.09, "knee": 0.065, "ankle": 0.05, "toe": 0.04, "shoulder": 0.07, "elbow": 0.05, "wrist": 0.04,
         "fingers": 0.035}


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--validator", default="")
    parser.add_argument("--cli", default="")
    args = parser.parse_args(argv)
    args.out = os.path.abspath(args.out)  # Blender's save operator refuses relative paths
    os.makedirs(args.out, exist_ok=True)
    return args


def build_body():
    names = list(JOINTS)
    mesh = bpy.data.meshes.new("Character")
    mesh.from_pydata([JOINTS[n] for n in names], [(names.index(a), names.index(b)) for a, b in EDGES], [])
    body = bpy.data.objects.new("Character", mesh)
    bpy.context.scene.collection.objects.link(body)
    skin = body.modifiers.new("Skin", 'SKIN')
    for index, name in enumerate(names):
        radius = RADII[name.split(".")[0]]
        mesh.skin_vertices[0].data[index].radius = (radius, radius * 0.8)
    mesh.skin_vertices[0].data[names.index("pelvis")].use_root = True
    subdivision = body.modifiers.new("Subdivision", 'SUBSURF')
    subdivision.levels = 2
    select_only(body)
    bpy.ops.object.modifier_apply(modifier=skin.name)
    bpy.ops.object.modifier_apply(modifier=subdivision.name)
    bpy.ops.object.shade_smooth()
    return body


def build_armature():
    data = bpy.data.armatures.new("CharacterRig")
    rig = bpy.data.objects.new("CharacterRig", data)
    bpy.context.scene.collection.objects.link(rig)
    select_only(rig)
    bpy.ops.object.mode_set(mode='EDIT')
    for name, parent, head, tail in BONES:
        bone = data.edit_bones.new(name)
        bone.head, bone.tail = JOINTS[head], JOINTS[tail]
        if parent:
            bone.parent = data.edit_bones[parent]
            bone.use_connect = tuple(bone.parent.tail) == tuple(bone.head)
    bpy.ops.object.mode_set(mode='OBJECT')
    return rig


def bind(body, rig):
    """Automatic weights (bone heat), then the clean-up an artist does: drop tiny weights and
    keep at most six influences a vertex (the library takes up to eight and keeps four)."""
    select_only(body)
    rig.select_set(True)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.parent_set(type='ARMATURE_AUTO')
    select_only(body)
    bpy.ops.object.vertex_group_clean(group_select_mode='ALL', limit=0.001)
    bpy.ops.object.vertex_group_limit_total(group_select_mode='ALL', limit=6)


def animate(rig):
    """A 24-frame wave: the right arm rises, the elbow bends, the left knee lifts; frame 16 is shown."""
    keys = {1: {}, 16: {"upper_arm.R": (0, -70, 0), "forearm.R": (0, 0, -60), "thigh.L": (-40, 0, 0),
                        "shin.L": (60, 0, 0), "spine": (0, 10, 0), "head": (0, 0, 20)},
            24: {"upper_arm.R": (0, -50, 0), "forearm.R": (0, 0, -30)}}
    for bone in rig.pose.bones:
        bone.rotation_mode = 'XYZ'
    for frame, pose in keys.items():
        for bone in rig.pose.bones:
            bone.rotation_euler = tuple(math.radians(a) for a in pose.get(bone.name, (0, 0, 0)))
            bone.keyframe_insert("rotation_euler", frame=frame)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    scene.frame_set(16)


def select_only(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


def validate(args, path):
    if not args.validator or not os.path.exists(args.validator):
        return "not run (tools/validate.mjs not set up)"
    run = subprocess.run(["node", args.validator, "--json", path], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True)
    if run.returncode not in (0, 1) or not run.stdout.strip():
        raise SystemExit("validator failed on %s: %s" % (path, run.stderr))
    issues = json.loads(run.stdout.strip().splitlines()[-1])["issues"]
    if issues["numErrors"]:
        raise SystemExit("%s: %d validator errors: %s" % (path, issues["numErrors"], issues["messages"]))
    return "%d errors, %d warnings" % (issues["numErrors"], issues["numWarnings"])


def main():
    args = arguments()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.preferences.addon_install(filepath=args.zip, overwrite=True)
    addon_utils.enable("io_scene_gltf2", default_set=True)
    if addon_utils.enable("skinpack", default_set=True) is None:
        raise SystemExit("the Skinpack add-on did not enable")
    from skinpack.io import storage

    body = build_body()
    rig = build_armature()
    bind(body, rig)
    animate(rig)
    blend_path = os.path.join(args.out, "character.blend")

    select_only(body)
    bpy.ops.skinpack.compress()
    stats = storage.load_result(body.data).stats

    pictures = []
    for mode in ("WEIGHT", "POSE"):
        bpy.ops.skinpack.preview_error(mode=mode)
        legend = body.data[storage.PREVIEW_KEY]
        path = os.path.join(args.out, "heatmap_%s.png" % mode.lower())
        skinpack_render.render_workbench(path, body, resolution=(640, 720),
                                         legend=skinpack_render.heat_map_legend(body))
        pictures.append((path, legend["maximum"], legend["scale"]))
    bpy.ops.skinpack.clear_preview()
    bpy.ops.wm.save_as_mainfile(filepath=blend_path)

    exports = []
    for mode in ("FALLBACK", "COMPACT"):
        path = os.path.join(args.out, "character_%s.glb" % mode.lower())
        select_only(body)
        bpy.ops.skinpack.export_gltf(filepath=path, mode=mode)
        exports.append((path, mode.lower(), os.path.getsize(path), validate(args, path)))
    decoded = ""
    if args.cli and os.path.exists(args.cli):
        decoded = os.path.join(args.out, "character_compact_decoded.glb")
        subprocess.run([args.cli, "decompress", exports[1][0], "-o", decoded], check=True)

    rows = [
        ("vertices", "%d" % stats["vertices"]),
        ("deform bones", "%d" % stats["joint_count"]),
        ("method", "%s, K = %d, n = %d" % (stats["method"].upper(), stats["influences"], stats["n"])),
        ("bits / vertex", "%.1f -> %.1f (glTF JOINTS+WEIGHTS -> Skinpack incl. table)"
         % (stats["input_bits_per_vertex"], stats["bits_per_vertex"])),
        ("ratio", "%.1f : 1" % stats["ratio"]),
        ("unique joint tuples", "%d (%d tuple bits + %d weight bits)" % (stats["unique_tuples"], stats["tuple_bits"],
                                                                      stats["weight_bits"])),
        ("max / RMS weight error", "%.2e / %.2e (bound %.2e)" % (stats["max_error"], stats["rms_error"],
                                                               stats["error_bound"])),
        ("pruned vertices", "%d (max pruning error %.3f)" % (stats["pruned_vertices"], stats["max_pruning_error"])),
    ]
    rows += [("heat map (%s)" % os.path.basename(p), "max %.2e, scale %.2e" % (m, s)) for p, m, s in pictures]
    rows += [("glTF %s" % mode, "%s, %d bytes, validator: %s" % (os.path.basename(p), size, v))
             for p, mode, size, v in exports]
    if decoded:
        rows.append(("skinpack decompress", os.path.basename(decoded)))
    rows.append(("scene", os.path.basename(blend_path)))
    width = max(len(r[0]) for r in rows)
    print("\nSkinpack demo (output in %s)\n" % args.out)
    print("| %s | %s |" % ("".ljust(width), "value"))
    print("|%s|%s|" % ("-" * (width + 2), "-" * 7))
    for key, value in rows:
        print("| %s | %s |" % (key.ljust(width), value))
    sys.stdout.flush()


try:
    main()
except SystemExit as error:
    print("demo failed: %s" % error)
    sys.stdout.flush()
    os._exit(1)
