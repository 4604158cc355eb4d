"""A/B: the decoded weights replace the originals, and the originals come back bit-exactly,
also after saving and reloading while the decoded weights are shown."""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402


def evaluated_positions(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    positions = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", positions)
    obj.evaluated_get(depsgraph).to_mesh_clear()
    return positions.reshape(-1, 3)


def pose_every_bone(obj):
    for bone in obj.find_armature().pose.bones:
        bone.rotation_mode = 'XYZ'
        bone.rotation_euler = (math.radians(15), 0.0, math.radians(10))
    bpy.context.view_layer.update()


def check_mesh_holds_decoded(obj, result):
    """Deform elements carry the decoded weights, sampled across the mesh."""
    from skinpack import gather
    counts, groups, weights = gather.read_elements(obj.data)
    decoded_joints, decoded_weights = result.decode()
    joint_names = result.info["joint_names"]
    group_joint = {i: joint_names.index(g.name) for i, g in enumerate(obj.vertex_groups) if g.name in joint_names}
    vertex_of = np.repeat(np.arange(len(counts)), counts)
    for element in range(0, len(weights), 97):
        vertex, group = vertex_of[element], groups[element]
        joint = group_joint.get(int(group))
        if joint is None:
            continue
        slots = np.nonzero((decoded_joints[vertex] == joint) & (decoded_weights[vertex] > 0))[0]
        expected = decoded_weights[vertex, slots[0]] if len(slots) else 0.0
        common.check(weights[element] == np.float32(expected),
                     "vertex %d group %d: %r, decoded %r" % (vertex, group, weights[element], expected))


def check_toggle_round_trip(obj, before, original_pose):
    from skinpack.io import storage
    bpy.ops.skinpack.compress()
    result = storage.load_result(obj.data)
    bpy.ops.skinpack.toggle_decoded()
    common.check(storage.showing_decoded(obj.data), "toggle did not switch to decoded")
    check_mesh_holds_decoded(obj, result)
    moved = np.linalg.norm(evaluated_positions(obj) - original_pose, axis=1)
    common.check(moved.max() > 0, "decoded weights do not change the deformation")
    print("A/B: max vertex shift in the test pose %.5f" % moved.max())

    # Compress refuses while decoded weights are shown.
    common.refusal(bpy.ops.skinpack.compress, "A/B", "RE_Player")  # it would compress the decoded weights

    bpy.ops.skinpack.toggle_decoded()
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "A/B off")
    common.check(not storage.showing_decoded(obj.data), "originals still stored after restore")
    common.check(np.array_equal(evaluated_positions(obj), original_pose), "deformation not restored")


def check_save_reload(args, before):
    """Toggle on, save, reload, toggle off: still bit-exact. Returns the reloaded object."""
    from skinpack.io import storage
    bpy.ops.skinpack.toggle_decoded()
    path = os.path.join(args.out, "ab_saved_decoded.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["RE_Player"]
    common.make_active(obj)
    common.check(storage.showing_decoded(obj.data), "decoded state lost on reload")
    bpy.ops.skinpack.toggle_decoded()
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "A/B off after reload")
    return obj


def check_stale_result_refused(obj, before):
    """Weights painted after compression: A/B and the pose preview refuse the stale result."""
    elements = obj.data.vertices[5].groups
    saved = np.empty(len(elements), dtype=np.float32)
    elements.foreach_get("weight", saved)
    elements.foreach_set("weight", saved * np.float32(0.5))
    for action in (bpy.ops.skinpack.toggle_decoded, lambda: bpy.ops.skinpack.preview_error(mode='POSE')):
        common.refusal(action, "changed since compression")
    elements.foreach_set("weight", saved)
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "stale refusals")


def check_edited_membership_refused(obj):
    """Membership edited while decoded: restoring refuses and keeps the stored originals."""
    from skinpack.io import storage
    bpy.ops.skinpack.toggle_decoded()
    obj.vertex_groups[obj.data.vertices[0].groups[0].group].remove([0])
    edited = common.weight_snapshot(obj.data)
    common.refusal(bpy.ops.skinpack.toggle_decoded, "changed", "RE_Player")
    common.assert_same_weights(edited, common.weight_snapshot(obj.data), "refused restore")
    common.check(storage.showing_decoded(obj.data), "originals dropped after a refused restore")


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    before = common.weight_snapshot(obj.data)
    common.check((before[2].view(np.float32) > 1.0).any(), "asset has no weight above 1: the clamp case is untested")
    pose_every_bone(obj)
    original_pose = evaluated_positions(obj)
    check_toggle_round_trip(obj, before, original_pose)
    obj = check_save_reload(args, before)
    check_stale_result_refused(obj, before)
    check_edited_membership_refused(obj)


common.run(main)
