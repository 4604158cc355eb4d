"""skinpack.preview_meshlets on RE_Player and the skinned cylinder, every builder and both modes:
the colour attribute maps meshlets one-to-one onto colours (or joint counts onto the ramp), the
stats on the object are the library's for the same input, the meshlets cover every triangle
within the limits, the weights stay bit-identical, Clear removes everything, errors leave the
mesh untouched, the preview is one undo step, Palette Effort reaches the library and lowers
RE_Player's palette sum, and a Workbench render of the preview is a real
picture (docs/images/meshlets_preview.png with --docs)."""

import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))
import skinpack_render as render  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402

BUILDERS = ('NAIVE', 'COMMON', 'SKIN')
LIMITS = {"max_vertices": 64, "max_triangles": 124, "palette_size": 32}
BUILDER_NAMES = {'NAIVE': "Naive", 'COMMON': "Common Influences", 'SKIN': "Skin-Aware"}
STAT_KEYS = ("meshlet_count", "mean_vertices", "mean_triangles", "mean_joints", "max_joints",
             "global_tuple_bits", "local_tuple_bits_mean", "local_tuple_bits_max")


def polygon_colors(mesh, attribute):
    """(P, 4) colour of each face; fails unless all corners of a face have the same colour."""
    colors = np.empty(len(mesh.loops) * 4, dtype=np.float32)
    attribute.data.foreach_get("color", colors)
    colors = colors.reshape(-1, 4)
    totals = np.empty(len(mesh.polygons), dtype=np.int64)
    starts = np.empty(len(mesh.polygons), dtype=np.int64)
    mesh.polygons.foreach_get("loop_total", totals)
    mesh.polygons.foreach_get("loop_start", starts)
    face_colors = colors[starts]
    for corner in range(int(totals.max())):
        has = totals > corner
        common.check((colors[starts[has] + corner] == face_colors[has]).all(),
                     "%s: corners of a face differ in colour" % mesh.name)
    return face_colors


def distinct_rows(rows):
    return len(np.unique(np.ascontiguousarray(rows), axis=0))


def reference_meshlets(obj, builder):
    """A second, independent call of the library on the same input."""
    from skinpack import meshlet_preview
    from skinpack.io import native
    inputs = meshlet_preview.read_inputs(obj, obj.data.skinpack.max_influences)
    options = native.meshlet_options(meshlet_preview.BUILDERS[builder], LIMITS["max_vertices"],
                                     LIMITS["max_triangles"], LIMITS["palette_size"])
    return inputs, native.build_meshlets(inputs.indices, inputs.positions, inputs.joints, inputs.weights, options)


def check_preview(obj, builder, mode):
    from skinpack import preview
    from skinpack.io import native
    what = "%s %s %s" % (obj.name, builder, mode)
    mesh = obj.data
    attribute = mesh.color_attributes.get(preview.MESHLET_ATTRIBUTE_NAME)
    common.check(attribute is not None, what + ": no colour attribute")
    common.check(attribute.domain == 'CORNER' and attribute.data_type == 'FLOAT_COLOR', what + ": attribute type")
    names = [a.name for a in mesh.color_attributes]
    common.check(mesh.color_attributes.render_color_index == names.index(preview.MESHLET_ATTRIBUTE_NAME)
                 and mesh.color_attributes.active_color_index == names.index(preview.MESHLET_ATTRIBUTE_NAME),
                 what + ": the preview is not the active and render colour")
    common.check(preview.ATTRIBUTE_NAME not in names, what + ": the error heat map is still there")
    common.check(bpy.context.scene.display.shading.color_type == 'VERTEX',
                 what + ": Workbench does not colour by attribute")

    inputs, reference = reference_meshlets(obj, builder)
    expected = native.meshlet_stats_dict(reference.stats)
    stored = obj.skinpack_meshlets
    common.check(stored.valid and stored.shown_builder == builder and stored.shown_mode == mode, what + ": stats flags")
    for key in STAT_KEYS:
        # FloatProperty stores float32.
        common.check(getattr(stored, key) == np.float32(expected[key]),
                     "%s: stat %s = %r, library %r" % (what, key, getattr(stored, key), expected[key]))

    # Invariants of the library's output on the Blender mesh.
    meshlets = reference.meshlets
    mesh.calc_loop_triangles()
    triangle_count = len(mesh.loop_triangles)
    common.check(expected["meshlet_count"] == len(meshlets) > 0, what + ": meshlet count")
    common.check(int(meshlets["triangle_count"].sum()) == triangle_count == expected["triangle_count"],
                 "%s: meshlets hold %d triangles, the mesh has %d" % (what, meshlets["triangle_count"].sum(),
                                                                     triangle_count))
    common.check(int(meshlets["vertex_count"].max()) <= LIMITS["max_vertices"], what + ": vertex limit")
    common.check(int(meshlets["triangle_count"].max()) <= LIMITS["max_triangles"], what + ": triangle limit")
    common.check(expected["max_joints"] == int(meshlets["joint_count"].max()) <= LIMITS["palette_size"],
                 what + ": palette limit")
    triangle_meshlet = reference.triangle_meshlet
    common.check(len(triangle_meshlet) == triangle_count and int(triangle_meshlet.max()) < len(meshlets),
                 what + ": triangle_meshlet out of range")
    common.check((np.bincount(triangle_meshlet, minlength=len(meshlets)) == meshlets["triangle_count"]).all(),
                 what + ": triangle_meshlet disagrees with the meshlets' triangle counts")

    # Colours: a face shows the meshlet of its first loop triangle.
    face_colors = polygon_colors(mesh, attribute)
    faces, first_triangles = np.unique(inputs.triangle_polygons, return_index=True)
    common.check(len(faces) == len(mesh.polygons), what + ": a face without triangles")
    face_meshlets = triangle_meshlet[first_triangles]
    shown = len(np.unique(face_meshlets))
    if mode == 'MESHLET':
        # One colour per meshlet and one meshlet per colour: the (meshlet, colour) pairs are as
        # many as the meshlets shown and as the colours.
        pairs = np.concatenate([face_meshlets[:, None].astype(np.float32), face_colors], axis=1)
        common.check(distinct_rows(face_colors) == shown == distinct_rows(pairs),
                     "%s: %d colours for %d meshlets shown" % (what, distinct_rows(face_colors), shown))
    else:
        joints = meshlets["joint_count"][face_meshlets].astype(np.float32)
        pairs = np.concatenate([joints[:, None], face_colors], axis=1)
        common.check(distinct_rows(face_colors) == len(np.unique(joints)) == distinct_rows(pairs),
                     what + ": colours do not follow the joints per meshlet")
        # The error heat map's ramp, from 0 to the palette size.
        ramp = preview.heat_colors(joints, float(LIMITS["palette_size"]))
        common.check(np.array_equal(face_colors, ramp), what + ": colours are not the ramp of the joint counts")
    print("%s: %d meshlets (%d shown), mean %.1f v / %.1f t / %.2f j, max %d j, tuple bits %d global, %.2f local"
          % (what, len(meshlets), shown, expected["mean_vertices"], expected["mean_triangles"],
             expected["mean_joints"], expected["max_joints"], expected["global_tuple_bits"],
             expected["local_tuple_bits_mean"]))
    return len(meshlets), shown


def check_panel(obj, builder_name, mode):
    texts = common.draw_skinpack_panel(obj)
    stats = obj.skinpack_meshlets
    common.check("Meshlets" in texts and texts.count("operator:skinpack.preview_meshlets") == 2,
                 "%s: no Meshlets box with two buttons: %s" % (obj.name, texts))
    for expected in (builder_name, "%d" % stats.meshlet_count, "%.1f" % stats.mean_vertices,
                     "%.1f" % stats.mean_triangles, "%.1f mean, %d max" % (stats.mean_joints, stats.max_joints),
                     "%d global \u2192 %.2f local (max %d)" % (stats.global_tuple_bits, stats.local_tuple_bits_mean,
                                                               stats.local_tuple_bits_max)):
        common.check(expected in texts, "%s: panel lacks %r: %s" % (obj.name, expected, texts))
    common.check(("Joints per meshlet" in texts) == (mode == 'JOINTS'),
                 "%s: legend of %s: %s" % (obj.name, mode, texts))
    return texts


def check_cleared(obj, color_type_before):
    from skinpack import preview
    common.check(preview.MESHLET_ATTRIBUTE_NAME not in obj.data.color_attributes, obj.name + ": Clear left the colours")
    common.check(not obj.skinpack_meshlets.valid, obj.name + ": Clear left the stats")
    common.check(bpy.context.scene.display.shading.color_type == color_type_before,
                 obj.name + ": Clear did not restore the scene's colour type")


def check_one_preview_at_a_time(args):
    """The error heat map and the meshlet colours replace each other; neither is exported."""
    from skinpack import preview
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    bpy.ops.skinpack.compress()
    bpy.ops.skinpack.preview_meshlets()
    bpy.ops.skinpack.preview_error(mode='WEIGHT')
    names = [a.name for a in obj.data.color_attributes]
    common.check(preview.ATTRIBUTE_NAME in names and preview.MESHLET_ATTRIBUTE_NAME not in names,
                 "error preview after meshlets: %s" % names)
    common.check("Mean triangles" not in common.draw_skinpack_panel(obj), "meshlet stats shown under the heat map")
    bpy.ops.skinpack.preview_meshlets(mode='JOINTS')
    names = [a.name for a in obj.data.color_attributes]
    common.check(preview.MESHLET_ATTRIBUTE_NAME in names and preview.ATTRIBUTE_NAME not in names,
                 "meshlets after error preview: %s" % names)
    common.check(preview.legend(obj.data) is None, "heat-map legend shown for the meshlet preview")
    path = os.path.join(args.out, "cylinder_meshlets.glb")
    bpy.ops.skinpack.export_gltf(filepath=path)
    primitives = [primitive for _, _, primitive in common.Glb(path).skinned_primitives()]
    common.check(len(primitives) > 0, path + ": no primitive exported")
    for primitive in primitives:
        common.check("COLOR_0" not in primitive["attributes"], "the meshlet colours were exported")


def check_undo(args):
    """The preview is one undo step. Runs first: background Blender keeps an undo stack only while
    the startup window exists, which opening a .blend drops (see test_undo.py)."""
    from skinpack import preview
    blend = common.asset(args, "skinned_cylinder.blend")
    bpy.ops.wm.append(directory=blend + "/Object/", files=[{"name": "Root"}, {"name": "Cylinder"}])
    common.make_active(bpy.data.objects["Cylinder"])
    common.check(len(bpy.context.window_manager.windows) == 1, "no window: the undo stack is unavailable")
    bpy.ops.ed.undo_push(message="appended")
    bpy.ops.skinpack.preview_meshlets('EXEC_DEFAULT', True)
    obj = bpy.data.objects["Cylinder"]
    common.check(preview.MESHLET_ATTRIBUTE_NAME in obj.data.color_attributes and obj.skinpack_meshlets.valid,
                 "the preview wrote nothing")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Cylinder"]
    common.check(preview.MESHLET_ATTRIBUTE_NAME not in obj.data.color_attributes and not obj.skinpack_meshlets.valid,
                 "undo kept the meshlet preview")


def check_errors(args):
    from skinpack import preview
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    before = common.weight_snapshot(obj.data)
    attributes = sorted(a.name for a in obj.data.attributes)
    common.refusal(lambda: bpy.ops.skinpack.preview_meshlets(mode='MESHLET', palette_size=1),
                   "RE_Player: triangle ", "(face ", "palette size 1")
    common.assert_same_weights(before, common.weight_snapshot(obj.data), "failed preview")
    common.check(sorted(a.name for a in obj.data.attributes) == attributes, "failed preview changed the attributes")
    common.check(not obj.skinpack_meshlets.valid, "failed preview stored stats")

    # A mesh without an armature.
    plain = bpy.data.objects.new("Plain", bpy.data.meshes.new("Plain"))
    plain.data.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    bpy.context.scene.collection.objects.link(plain)
    common.make_active(plain)
    common.refusal(bpy.ops.skinpack.preview_meshlets, "Plain is not deformed by an armature")
    common.check(preview.MESHLET_ATTRIBUTE_NAME not in plain.data.color_attributes, "colours on a failed mesh")


def check_triangulated(args):
    """On an all-triangle mesh every meshlet is visible: distinct colours == meshlet count."""
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    modifier = obj.modifiers.new("triangulate", 'TRIANGULATE')
    bpy.ops.object.modifier_move_to_index(modifier=modifier.name, index=0)
    bpy.ops.object.modifier_apply(modifier=modifier.name)
    for builder in BUILDERS:
        bpy.ops.skinpack.preview_meshlets(mode='MESHLET', builder=builder, **LIMITS)
        count, shown = check_preview(obj, builder, 'MESHLET')
        common.check(count == shown, "triangulated cylinder %s: %d meshlets, %d shown" % (builder, count, shown))


def check_palette_effort(args):
    """Palette Effort: the preview passes it to the library (the stats are those of a direct call with
    it), and on RE_Player it lowers the palette sum at the same meshlet count."""
    from skinpack import meshlet_preview
    from skinpack.io import native
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    sums = {}
    for effort in (0, 300):
        common.check(bpy.ops.skinpack.preview_meshlets(mode='JOINTS', builder='SKIN', palette_effort=effort,
                                                       **LIMITS) == {'FINISHED'}, "effort %d" % effort)
        inputs = meshlet_preview.read_inputs(obj, obj.data.skinpack.max_influences)
        options = native.meshlet_options('skin', LIMITS["max_vertices"], LIMITS["max_triangles"],
                                         LIMITS["palette_size"], effort)
        reference = native.meshlet_stats_dict(
            native.build_meshlets(inputs.indices, inputs.positions, inputs.joints, inputs.weights, options).stats)
        stats = obj.skinpack_meshlets
        common.check(stats.meshlet_count == reference["meshlet_count"] and
                     stats.mean_joints == np.float32(reference["mean_joints"]),
                     "effort %d: the preview's stats are not the library's" % effort)
        sums[effort] = (stats.meshlet_count, round(stats.mean_joints * stats.meshlet_count))
    print("RE_Player palette effort 0 -> 300: %s -> %s meshlets / entries" % (sums[0], sums[300]))
    common.check(sums[300][0] <= sums[0][0] and sums[300][1] < sums[0][1],
                 "effort 300 did not lower the palette sum: %s -> %s" % (sums[0], sums[300]))
    obj.skinpack_meshlets.palette_effort = 300
    common.draw_skinpack_panel(obj)  # hands the setting to the preview buttons


def render_preview(args):
    obj = common.open_asset(args, "RE_Player_female.blend", "RE_Player")
    bpy.ops.skinpack.preview_meshlets(mode='MESHLET', builder='SKIN')
    path = render.render_workbench(os.path.join(args.out, "meshlets_preview.png"), obj)
    covered, colors, pixels = common.picture_summary(render.image_pixels(path))
    print("%s: %.1f%% covered, %d colours" % (os.path.basename(path), 100 * covered, colors))
    common.check(covered > 0.05, "%s: the mesh covers %.1f%% of the frame" % (path, 100 * covered))
    common.check(colors > 20, "%s: only %d colours: a flat image" % (path, colors))
    # Distinct meshlet colours span every channel, unlike a shaded grey mesh.
    common.check(min(np.ptp(pixels, axis=0)) > 0.3, "%s: the meshlet colours do not show" % path)
    if args.docs:
        os.makedirs(args.docs, exist_ok=True)
        shutil.copy(path, os.path.join(args.docs, os.path.basename(path)))


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    check_undo(args)
    for blend, name in (("RE_Player_female.blend", "RE_Player"), ("skinned_cylinder.blend", "Cylinder")):
        obj = common.open_asset(args, blend, name)
        color_type_before = bpy.context.scene.display.shading.color_type
        before = common.weight_snapshot(obj.data)
        for builder in BUILDERS:
            for mode in ('MESHLET', 'JOINTS'):
                common.check(bpy.ops.skinpack.preview_meshlets(mode=mode, builder=builder, **LIMITS) == {'FINISHED'},
                             "%s %s %s did not finish" % (name, builder, mode))
                check_preview(obj, builder, mode)
                check_panel(obj, BUILDER_NAMES[builder], mode)
        common.assert_same_weights(before, common.weight_snapshot(obj.data), name + " after the previews")
        bpy.ops.skinpack.clear_preview()
        check_cleared(obj, color_type_before)
        common.check("Mean triangles" not in common.draw_skinpack_panel(obj), name + ": panel shows stats after Clear")
        common.assert_same_weights(before, common.weight_snapshot(obj.data), name + " after Clear")
    check_triangulated(args)
    check_one_preview_at_a_time(args)
    check_errors(args)
    check_palette_effort(args)
    render_preview(args)


common.run(main)
