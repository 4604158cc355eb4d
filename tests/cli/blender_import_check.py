"""Imports a glTF file with Blender's own importer and checks that its skins came through.

    blender -b --factory-startup --python-exit-code 1 --python blender_import_check.py -- FILE.glb

A fallback-mode file must load in any glTF viewer that ignores SKINPACK_packed_skin: here every
skinned mesh must come back with an Armature modifier and vertex groups, and every vertex must
have a non-zero weight in some group (as JOINTS_0/WEIGHTS_0 say it has).
"""
import sys

import numpy

# Blender 3.4's importer uses numpy.bool, removed in numpy 1.24 (Debian 12 ships 1.24).
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_

import bpy  # noqa: E402

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
result = bpy.ops.import_scene.gltf(filepath=path)
if result != {"FINISHED"}:
    raise SystemExit("import of %s failed: %s" % (path, result))

skinned = 0
for obj in bpy.data.objects:
    if obj.type != "MESH" or not any(m.type == "ARMATURE" for m in obj.modifiers):
        continue
    skinned += 1
    mesh = obj.data
    if not obj.vertex_groups:
        raise SystemExit("%s: skinned mesh without vertex groups" % obj.name)
    unweighted = sum(1 for v in mesh.vertices if not any(g.weight > 0 for g in v.groups))
    if unweighted:
        raise SystemExit("%s: %d of %d vertices have no weight" % (obj.name, unweighted, len(mesh.vertices)))
    print("%s: %d vertices, %d vertex groups, all weighted" % (obj.name, len(mesh.vertices), len(obj.vertex_groups)))
if skinned == 0:
    raise SystemExit("%s: no skinned mesh after import" % path)
print("OK: %d skinned mesh(es) imported from %s" % (skinned, path))
