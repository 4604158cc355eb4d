"""Invalid input and failing operators: a clear report naming the object and how many
vertices, never a traceback, and the mesh stays bit-identical."""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402


def expect_failure(obj, operator, *fragments, **properties):
    """Runs the operator, which must fail with a message containing every fragment, and checks
    that the weights and the stored result are untouched."""
    from skinpack.io import storage
    common.make_active(obj)
    before = common.weight_snapshot(obj.data)
    stored = obj.data.get(storage.RESULT_KEY)
    stored = dict(stored.to_dict()) if stored is not None else None
    common.refusal(lambda: operator(**properties), *fragments)
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "after failed operator on " + obj.name)
    after = obj.data.get(storage.RESULT_KEY)
    common.check((after.to_dict() if after is not None else None) == stored, "stored result changed on failure")


def duplicate(obj, name):
    copy = obj.copy()
    copy.data = obj.data.copy()
    copy.name = copy.data.name = name
    bpy.context.scene.collection.objects.link(copy)
    return copy


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack.io import native
    compress = bpy.ops.skinpack.compress

    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    vertex_count = len(obj.data.vertices)

    # No armature.
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.active_object
    cube.name = "LonelyCube"
    expect_failure(cube, compress, "LonelyCube", "armature")

    # No group is a deform bone.
    renamed = duplicate(obj, "RenamedGroups")
    for group in renamed.vertex_groups:
        group.name = "not_a_bone_" + group.name
    expect_failure(renamed, compress, "RenamedGroups", "no vertex group named after a deform bone")

    # Vertices without weights: 7 of them lose every group.
    unweighted = duplicate(obj, "Unweighted")
    for group in unweighted.vertex_groups:
        group.remove([0, 1, 2, 3, 4, 5, 6])
    expect_failure(unweighted, compress, "Unweighted", "7 of %d vertices" % vertex_count)

    # Non-finite and negative weights (written raw: the RNA setter would clamp them).
    for label, value, fragment in (("NaNWeights", np.nan, "non-finite"), ("NegativeWeights", -0.5, "negative")):
        bad = duplicate(obj, label)
        for index in (3, 9, 27):
            elements = bad.data.vertices[index].groups
            values = np.empty(len(elements), dtype=np.float32)
            elements.foreach_get("weight", values)
            values[0] = value
            elements.foreach_set("weight", values)
        expect_failure(bad, compress, label, "3 vertices", fragment)

    # The library refuses a budget (tuple index alone needs more than 4 bits here), or the error
    # target is out of reach: reported with the object name, nothing changes.
    player = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    bpy.ops.skinpack.compress()  # a stored result that must survive the failures below
    player.data.skinpack.budget, player.data.skinpack.custom_bits = 'CUSTOM', 4
    expect_failure(player, compress, "RE_Player:")
    player.data.skinpack.budget, player.data.skinpack.max_error = 'ERROR', 1e-9
    player.data.skinpack.method = 'FIXED'
    player.data.skinpack.max_influences = 4
    expect_failure(player, compress, "RE_Player", "max error")

    # More joints than the format holds: the library refuses, the binding raises.
    try:
        native.compress(np.zeros((4, 1), np.uint16), np.ones((4, 1), np.float32), native.SP_MAX_JOINTS + 1,
                        native.make_options("oss", 4, vertex_bits=32))
    except native.SkinpackError as error:
        print("too many joints: %s" % error)
    else:
        raise AssertionError("65536 joints accepted")

    # Previews and A/B without a result, export without a file: reports, no traceback.
    fresh = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    common.check(not bpy.ops.skinpack.preview_error.poll(), "preview offered without a result")
    common.check(not bpy.ops.skinpack.toggle_decoded.poll(), "A/B offered without a result")
    expect_failure(fresh, bpy.ops.skinpack.export_gltf, "No file path", filepath="")


common.run(main)
