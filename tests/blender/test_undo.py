"""Undo: Compress and the A/B toggle are single undo steps that undo bit-exactly.

Blender keeps its undo stack in background mode only while the startup window exists, which
opening a .blend drops; so the cylinder rig is appended into the factory scene instead.
Operators are called with undo=True, as the UI calls them.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack.io import storage

    blend = common.asset(args, "skinned_cylinder.blend")
    bpy.ops.wm.append(directory=blend + "/Object/", files=[{"name": "Root"}, {"name": "Cylinder"}])
    obj = bpy.data.objects["Cylinder"]
    common.make_active(obj)
    common.check(len(bpy.context.window_manager.windows) == 1, "no window: the undo stack is unavailable")
    before = common.weight_snapshot(obj.data)
    bpy.ops.ed.undo_push(message="appended")

    bpy.ops.skinpack.compress('EXEC_DEFAULT', True)
    common.check(storage.RESULT_KEY in bpy.data.objects["Cylinder"].data, "compress stored nothing")
    bpy.ops.ed.undo()
    common.check(storage.RESULT_KEY not in bpy.data.objects["Cylinder"].data, "undo kept the compression result")
    bpy.ops.ed.redo()
    common.check(storage.RESULT_KEY in bpy.data.objects["Cylinder"].data, "redo lost the compression result")

    common.make_active(bpy.data.objects["Cylinder"])
    bpy.ops.skinpack.toggle_decoded('EXEC_DEFAULT', True)
    obj = bpy.data.objects["Cylinder"]
    common.check(storage.showing_decoded(obj.data), "toggle did not switch")
    decoded = common.weight_snapshot(obj.data)
    common.check(not (decoded[2] == before[2]).all(), "decoded weights equal the originals: nothing to undo")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Cylinder"]
    common.check(not storage.showing_decoded(obj.data), "undo left the A/B state on")
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "undo of the A/B toggle")
    print("undo/redo of compress and A/B verified")


common.run(main)
