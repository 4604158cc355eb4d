"""Shared helpers of the headless Blender tests (run inside `blender -b --python`).

Arguments after `--`: --zip ADDON_ZIP --shared SHARED_DIR --out OUTPUT_DIR [--cli SKINPACK]
[--validator tools/validate.mjs] [--layout LAYOUT_JSON_PROGRAM]. The add-on is installed from
the built zip into BLENDER_USER_SCRIPTS (a per-test temporary folder set by ctest).
"""

import argparse
import os
import shutil
import sys

import addon_utils
import bpy
import numpy

# Debian's Blender 3.4 glTF importer uses np.bool, which numpy >= 1.24 removed.
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True)
    parser.add_argument("--shared", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--cli", default="")
    parser.add_argument("--validator", default="")
    parser.add_argument("--layout", default="")
    parser.add_argument("--docs", default="", help="also copy rendered pictures here (docs/images)")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    return args


def install_addon(zip_path):
    """Installs the zip into the (temporary) user scripts folder and enables it and glTF."""
    user_scripts = os.environ.get("BLENDER_USER_SCRIPTS", "")
    check(user_scripts != "" and not user_scripts.startswith(os.path.expanduser("~/.config")),
          "tests must run with BLENDER_USER_SCRIPTS set to a scratch folder, got %r" % user_scripts)
    # Start from an empty scratch folder: an earlier run's copy must not be what gets tested.
    shutil.rmtree(os.path.join(user_scripts, "addons", "skinpack"), ignore_errors=True)
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    addon_utils.enable("io_scene_gltf2", default_set=True)
    module = addon_utils.enable("skinpack", default_set=True, handle_error=_raise)
    assert module is not None, "skinpack did not enable"
    assert "skinpack" in bpy.context.preferences.addons
    return module


def _raise(error):
    raise error


def asset(args, name):
    return os.path.join(args.shared, "assets", name)


def open_asset(args, name, object_name):
    bpy.ops.wm.open_mainfile(filepath=asset(args, name))
    obj = bpy.data.objects[object_name]
    make_active(obj)
    return obj


def make_active(obj):
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


def skinned_meshes():
    """Mesh objects deformed by an armature that have at least one deform group."""
    result = []
    for obj in bpy.data.objects:
        if obj.type != 'MESH' or obj.find_armature() is None:
            continue
        bones = {b.name for b in obj.find_armature().data.bones if b.use_deform}
        if any(g.name in bones for g in obj.vertex_groups):
            result.append(obj)
    return result


def weight_snapshot(mesh):
    """Every vertex-group element (vertex, group, weight bits) in mesh order: bit-exact compare."""
    entries = []
    for vertex in mesh.vertices:
        for element in vertex.groups:
            entries.append((vertex.index, element.group, element.weight))
    counts = numpy.array([e[0] for e in entries], dtype=numpy.int64)
    groups = numpy.array([e[1] for e in entries], dtype=numpy.int64)
    weights = numpy.array([e[2] for e in entries], dtype=numpy.float32)
    return counts, groups, weights.view(numpy.uint32)


def assert_same_weights(before, after, what):
    for a, b, label in zip(before, after, ("vertices", "groups", "weight bits")):
        assert a.shape == b.shape and (a == b).all(), "%s: %s differ" % (what, label)


def check(condition, message):
    if not condition:
        raise AssertionError(message)


def refusal(call, *fragments, traceback_allowed=False):
    """Runs call, which must fail with a RuntimeError (an operator's error report) whose text
    holds every fragment and, unless traceback_allowed, no traceback; returns the text."""
    try:
        call()
    except RuntimeError as error:
        message = str(error)
    else:
        raise AssertionError("not refused; expected a report with %s" % (fragments,))
    check(traceback_allowed or "Traceback" not in message, "traceback instead of a report: %s" % message)
    for fragment in fragments:
        check(fragment in message, "report %r lacks %r" % (message, fragment))
    print("refused: %s" % message.strip().splitlines()[-1])
    return message


def run(main):
    """Runs main() and exits non-zero with the traceback on failure (also outside --python-exit-code)."""
    try:
        main()
    except BaseException:
        import traceback
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
    print("PASSED")
    sys.stdout.flush()


# --- glTF files -------------------------------------------------------------------------------

GLTF_COMPONENTS = {5121: "<u1", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
GLTF_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


class Glb:
    """A .glb read back with nothing but the standard library and numpy."""

    def __init__(self, path):
        import json
        import struct
        with open(path, "rb") as handle:
            data = handle.read()
        magic, version, length = struct.unpack_from("<4sII", data, 0)
        check(magic == b"glTF" and version == 2 and length == len(data), "%s: not a valid GLB header" % path)
        json_length, json_type = struct.unpack_from("<I4s", data, 12)
        check(json_type == b"JSON", "%s: first chunk is not JSON" % path)
        self.json = json.loads(data[20:20 + json_length])
        offset = 20 + json_length
        self.bin = b""
        if offset < len(data):
            bin_length, bin_type = struct.unpack_from("<I4s", data, offset)
            check(bin_type == b"BIN\x00", "%s: second chunk is not BIN" % path)
            self.bin = data[offset + 8:offset + 8 + bin_length]

    def accessor(self, index):
        accessor = self.json["accessors"][index]
        view = self.json["bufferViews"][accessor["bufferView"]]
        width = GLTF_WIDTHS[accessor["type"]]
        dtype = numpy.dtype(GLTF_COMPONENTS[accessor["componentType"]])
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        stride = view.get("byteStride", width * dtype.itemsize)
        rows = numpy.ndarray((accessor["count"], width), dtype=dtype, buffer=self.bin, offset=start,
                             strides=(stride, dtype.itemsize))
        return numpy.array(rows)

    def skinned_primitives(self):
        for mesh_index, mesh in enumerate(self.json.get("meshes", [])):
            for primitive_index, primitive in enumerate(mesh["primitives"]):
                yield mesh_index, primitive_index, primitive


def joint_weight_maps(joints, weights):
    """Per vertex {joint: weight} of the non-zero influences (order-free comparison)."""
    result = []
    for joint_row, weight_row in zip(joints.tolist(), weights.tolist()):
        entry = {}
        for joint, weight in zip(joint_row, weight_row):
            if weight > 0:
                entry[joint] = entry.get(joint, 0.0) + weight
        result.append(entry)
    return result


def max_map_difference(a, b):
    worst = 0.0
    for left, right in zip(a, b):
        for joint in set(left) | set(right):
            worst = max(worst, abs(left.get(joint, 0.0) - right.get(joint, 0.0)))
    return worst


# --- rendered pictures ------------------------------------------------------------------------

def picture_summary(pixels):
    """(covered fraction, quantised colour count, covered RGB rows) of an (H, W, C) render: the
    background is the median of the first and last rows' pixels, 'covered' differs from it."""
    flat = pixels[:, :, :3].reshape(-1, 3)
    background = numpy.median(numpy.concatenate([flat[:50], flat[-50:]]), axis=0)
    covered = numpy.abs(flat - background).max(axis=1) > 0.05
    quantised = numpy.unique((flat[covered] * 16).astype(numpy.int32), axis=0)
    return float(covered.mean()), len(quantised), flat[covered]


# --- panels -----------------------------------------------------------------------------------

class RecordingLayout:
    """Stands in for UILayout: records every label and operator so a panel's draw() can be
    checked headless (background mode has no UI to draw into)."""

    def __init__(self, texts):
        self.texts = texts
        self.use_property_split = self.use_property_decorate = False
        self.enabled = self.active = True
        self.scale_y = 1.0

    def label(self, text="", icon='NONE'):
        self.texts.append(text)

    def prop(self, *args, **kwargs):
        pass

    def operator(self, idname, **kwargs):
        self.texts.append("operator:" + idname)
        return type("Properties", (), {})()

    def row(self, **kwargs):
        return self

    column = box = grid_flow = row


def draw_skinpack_panel(obj):
    """The texts the Skinpack panel draws for obj."""
    from skinpack import panel
    texts = []
    fake = type("FakePanel", (), {"layout": RecordingLayout(texts)})()
    context = type("Context", (), {"object": obj, "window_manager": bpy.context.window_manager})()
    check(panel.SKINPACK_PT_skin.poll(context), "panel does not poll for %s" % obj.name)
    panel.SKINPACK_PT_skin.draw(fake, context)
    return texts


def rigged_grid(name, bone_count, influences, subdivisions=0):
    """A grid skinned to a chain of bone_count bones; vertex i has `influences` distinct bones
    with distinct weights (the strongest first), so the kept four are unambiguous."""
    bpy.ops.object.armature_add(enter_editmode=True)
    armature = bpy.context.active_object
    armature.name = name + "_Rig"
    bones = armature.data.edit_bones
    bones[0].name = "B0"
    for index in range(1, bone_count):
        bone = bones.new("B%d" % index)
        bone.head = (0, 0, index * 0.2)
        bone.tail = (0, 0, index * 0.2 + 0.2)
    bpy.ops.object.mode_set(mode='OBJECT')
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=12, size=2)
    obj = bpy.context.active_object
    obj.name = obj.data.name = name
    groups = [obj.vertex_groups.new(name="B%d" % index) for index in range(bone_count)]
    rng = numpy.random.default_rng(bone_count * 100 + influences)
    for vertex in obj.data.vertices:
        chosen = rng.choice(bone_count, influences, replace=False)
        weights = numpy.sort(rng.random(influences) + 0.05)[::-1]
        weights /= weights.sum()
        for group, weight in zip(chosen, weights):
            groups[group].add([vertex.index], float(weight), 'REPLACE')
    if subdivisions:
        modifier = obj.modifiers.new("Subdivision", 'SUBSURF')
        modifier.levels = subdivisions
        bpy.ops.object.modifier_apply(modifier=modifier.name)
    obj.modifiers.new("Armature", 'ARMATURE').object = armature
    return obj


def weight_totals(pairs):
    """({key: sum of weights}, {key: how many}) over (key, weight) pairs with a non-zero weight."""
    sums, counts = {}, {}
    for key, weight in pairs:
        if weight > 0:
            sums[key] = sums.get(key, 0.0) + weight
            counts[key] = counts.get(key, 0) + 1
    return sums, counts


def vertex_group_weights(obj):
    """(vertex group name, weight) of every vertex's group elements."""
    names = [g.name for g in obj.vertex_groups]
    return ((names[e.group], e.weight) for vertex in obj.data.vertices for e in vertex.groups)
