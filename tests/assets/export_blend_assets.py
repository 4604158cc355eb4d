"""Exports the open .blend file to glTF binary with Blender's default settings.

    blender -b FILE.blend --factory-startup --python-exit-code 1 \
        --python tests/assets/export_blend_assets.py -- OUT.glb [--objects NAME,NAME...]

Which objects are exported:
  * --objects NAME,...: those objects (and nothing else);
  * otherwise, if the file has an object named RE_Player (RE_Player_female.blend, which also
    holds many unskinned helper meshes): RE_Player and its armature 'rig';
  * otherwise every object (RobotExpressive.blend, skinned_cylinder.blend).
Everything else is the glTF exporter's default, so the result is "Blender's default export"
for the benchmarks. Fails (non-zero exit with --python-exit-code 1) if the output has no skin.
"""
import os
import struct
import json
import sys

import bpy

# Objects to export for files that need a selection, keyed by a marker object.
SELECTIONS = {"RE_Player": ["RE_Player", "rig"]}


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if not args:
        raise SystemExit("usage: blender -b FILE --python export_blend_assets.py -- OUT.glb [--objects A,B]")
    out, objects = args[0], None
    if "--objects" in args:
        objects = args[args.index("--objects") + 1].split(",")
    return out, objects


def glb_has_skin(path):
    with open(path, "rb") as f:
        data = f.read()
    length = struct.unpack_from("<I", data, 12)[0]
    document = json.loads(data[20:20 + length])
    return bool(document.get("skins"))


def main():
    out, objects = parse_args(sys.argv)
    if objects is None:
        for marker, names in SELECTIONS.items():
            if marker in bpy.data.objects:
                objects = names
    if objects is not None:
        missing = [name for name in objects if name not in bpy.data.objects]
        if missing:
            raise SystemExit("objects not in %s: %s" % (bpy.data.filepath, ", ".join(missing)))
        for obj in bpy.context.view_layer.objects:
            obj.select_set(obj.name in objects)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", use_selection=objects is not None)
    if not glb_has_skin(out):
        raise SystemExit("%s: the export has no skin" % out)
    print("exported %s -> %s" % (bpy.data.filepath, out))


main()
