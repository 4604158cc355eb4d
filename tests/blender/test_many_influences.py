"""More than 8 influences (a 6-influence mesh subdivided, rigs with 9 and 12): Compress, the
meshlet preview and the glTF export (every influence, JOINTS_0..2) take them all, the library
keeps the K strongest, and the pruning is reported by object name (operator report, panel,
export report); the exported file decodes to the library's prepared weights within the bound."""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402

EXTENSION = "SKINPACK_packed_skin"


def most_influences(obj):
    deform = {g.index for g in obj.vertex_groups}
    return max(sum(1 for e in v.groups if e.group in deform and e.weight > 0) for v in obj.data.vertices)


def check_compress(obj):
    from skinpack.io import storage
    common.make_active(obj)
    before = common.weight_snapshot(obj.data)
    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "%s: compress refused" % obj.name)
    stats = storage.load_result(obj.data).stats
    common.check(stats["influences"] == 4 and stats["pruned_vertices"] > 0 and stats["max_pruning_error"] > 0,
                 "%s: no pruning reported: %s" % (obj.name, stats))
    texts = common.draw_skinpack_panel(obj)
    expected = "pruned to 4 influences (up to %d before)" % most_influences(obj)
    common.check(any(expected in t for t in texts), "%s: panel lacks %r: %s" % (obj.name, expected, texts))
    common.assert_same_weights(before, common.weight_snapshot(obj.data), obj.name + " after compress")
    common.check(bpy.ops.skinpack.preview_meshlets(mode='JOINTS') == {'FINISHED'}, "%s: meshlet preview" % obj.name)
    bpy.ops.skinpack.clear_preview()
    return stats


def check_export(args, obj, mode):
    """One-click export with every influence: pruning reported by object name, file decodes to
    the library's prepared weights of a plain all-influences export within maxError."""
    from skinpack.blender.exp import gltf2_skinpack_export as exporter
    from skinpack.io import native
    common.make_active(obj)
    path = os.path.join(args.out, "%s_%s.glb" % (obj.name, mode.lower()))
    common.check(bpy.ops.skinpack.export_gltf(filepath=path, mode=mode) == {'FINISHED'}, "export " + mode)
    warnings = exporter.last_report.warnings()
    common.check(any(w.startswith(obj.name + ": ") and "pruned to 4 influences" in w for w in warnings),
                 "%s %s: pruning not reported by object name: %s" % (obj.name, mode, warnings))
    texts = common.draw_skinpack_panel(obj)
    common.check(any(t.startswith("Last glTF export: 1 skinned primitives compressed") and obj.name in t for t in texts)
                 and any(t.startswith(obj.name + ": ") and "pruned" in t for t in texts),
                 "%s: the panel does not show the export's pruning: %s" % (obj.name, texts))

    plain_path = os.path.join(args.out, "%s_plain.glb" % obj.name)
    obj.find_armature().select_set(True)
    bpy.ops.export_scene.gltf(filepath=plain_path, export_format='GLB', use_selection=True,
                              export_all_influences=True)
    plain, packed = common.Glb(plain_path), common.Glb(path)
    ((_, _, p_plain),), ((_, _, p_packed),) = list(plain.skinned_primitives()), list(packed.skinned_primitives())
    sets = sorted(k for k in p_plain["attributes"] if k.startswith("JOINTS_"))
    common.check(len(sets) >= 3, "%s: the plain export has %s, expected every influence" % (obj.name, sets))
    extension = p_packed["extensions"][EXTENSION]
    if mode == 'COMPACT':
        common.check("JOINTS_1" not in p_packed["attributes"] and EXTENSION in packed.json["extensionsRequired"],
                     "%s: compact file keeps JOINTS_1 or does not require the extension" % obj.name)
    joints = np.concatenate([plain.accessor(p_plain["attributes"][k]) for k in sets], axis=1)
    weights = np.concatenate([plain.accessor(p_plain["attributes"]["WEIGHTS_" + k[7:]]) for k in sets], axis=1)
    reference_joints, reference_weights = native.prepare_influences(joints, weights, extension["jointCount"], 4)
    decoded_joints, decoded_weights = native.decompress(
        extension["method"], extension["influences"], extension["n"], extension.get("axisSamples", []),
        packed.accessor(extension["vertices"]).ravel(), len(joints), extension["tupleBits"],
        packed.accessor(extension["tupleTable"]).ravel(), extension["jointCount"])
    difference = common.max_map_difference(common.joint_weight_maps(reference_joints, reference_weights),
                                           common.joint_weight_maps(decoded_joints, decoded_weights))
    common.check(difference <= extension["maxError"] + 1e-6, "%s %s: decoded weights %g from the prepared ones"
                 % (obj.name, mode, difference))
    print("%s %s: %d-wide skin exported, decoded within %.2g of the library's four strongest"
          % (obj.name, mode, joints.shape[1], difference))


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    common.install_addon(args.zip)
    subdivided = common.rigged_grid("Subdivided6", 10, 6, subdivisions=1)
    common.check(most_influences(subdivided) > 8, "subdividing did not produce more than 8 influences")
    nine = common.rigged_grid("Nine", 16, 9)
    twelve = common.rigged_grid("Twelve", 300, 12)
    for obj in (subdivided, nine, twelve):
        check_compress(obj)
    for obj in (nine, twelve):
        for mode in ("FALLBACK", "COMPACT"):
            check_export(args, obj, mode)


common.run(main)
