"""Importing SKINPACK_packed_skin goes through the library's sp_validate_packed.

The spec's example files (docs/extension/conformance/examples) import with their expected
decoded weights. Copies broken in one way each (a code outside the simplex, a joint weighted
in two slots, a wrong vertex count, integers a reader must not truncate, a skin smaller than
jointCount, primitives sharing the packed words with other properties, broken meshlets) must
stop the import with a message naming the file, mesh, primitive and the library's reason, and
leave the scene without a new object, mesh or armature. Files of skinpack compress --meshopt
(with --cli) are refused naming EXT_meshopt_compression, which Blender's importer cannot decode.
"""

import json
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402
import numpy as np  # noqa: E402

EXTENSION = "SKINPACK_packed_skin"
EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "extension",
                        "conformance", "examples")


class EditableGlb(common.Glb):
    """A .glb whose JSON and BIN chunk can be edited and written back."""

    def __init__(self, path):
        super().__init__(path)
        self.bin = bytearray(self.bin)

    def extension(self, mesh=0, primitive=0):
        return self.json["meshes"][mesh]["primitives"][primitive]["extensions"][EXTENSION]

    def set_row(self, accessor_index, row, values):
        """Overwrites row `row` of a tightly packed accessor."""
        accessor = self.json["accessors"][accessor_index]
        view = self.json["bufferViews"][accessor["bufferView"]]
        dtype = np.dtype(common.GLTF_COMPONENTS[accessor["componentType"]])
        width = common.GLTF_WIDTHS[accessor["type"]]
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0) + row * width * dtype.itemsize
        self.bin[start:start + width * dtype.itemsize] = np.asarray(values, dtype=dtype).tobytes()

    def write(self, path):
        text = json.dumps(self.json).encode("utf-8")
        text += b" " * (-len(text) % 4)
        payload = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        with open(path, "wb") as handle:
            handle.write(struct.pack("<4sII", b"glTF", 2, 28 + len(text) + len(payload)))
            handle.write(struct.pack("<I4s", len(text), b"JSON") + text)
            handle.write(struct.pack("<I4s", len(payload), b"BIN\x00") + payload)
        return path


def expected_maps(name):
    """Per vertex {joint: weight} of the example's expected decoded skin."""
    with open(os.path.join(EXAMPLES, name + ".json")) as handle:
        primitive = json.load(handle)["primitives"][0]
    weights = np.array([[struct.unpack("<f", bytes.fromhex(w)[::-1])[0] for w in row] for row in primitive["weights"]],
                       dtype=np.float32)
    return np.array(primitive["joints"]), weights


def data_counts():
    return len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.armatures)


def import_valid(name):
    """The example imports; each joint's imported weight sum and influence count are the expected."""
    glb = common.Glb(os.path.join(EXAMPLES, name + ".glb"))
    # Blender names a nameless node Node_<index>.
    joint_names = [glb.json["nodes"][j].get("name") or "Node_%d" % j for j in glb.json["skins"][0]["joints"]]
    joints, weights = expected_maps(name)
    expected_sum, expected_count = common.weight_totals(
        (joint_names[joint], weight) for joint_row, weight_row in zip(joints.tolist(), weights.tolist())
        for joint, weight in zip(joint_row, weight_row))
    existing = set(bpy.data.objects)
    bpy.ops.import_scene.gltf(filepath=os.path.join(EXAMPLES, name + ".glb"))
    imported = [o for o in bpy.data.objects if o not in existing and o.type == 'MESH']
    common.check(len(imported) == 1, "%s: %d meshes imported" % (name, len(imported)))
    obj = imported[0]
    got_sum, got_count = common.weight_totals(common.vertex_group_weights(obj))
    common.check(got_count == expected_count, "%s: influence counts %s, expected %s"
                 % (name, got_count, expected_count))
    worst = max(abs(got_sum[k] - expected_sum[k]) for k in expected_sum)
    common.check(worst < 1e-5, "%s: weight sums differ by %g" % (name, worst))
    print("%s: imports with the expected weights of %d joints" % (name, len(expected_sum)))
    for obj in [o for o in bpy.data.objects if o not in existing]:
        bpy.data.objects.remove(obj)


def expect_refusal(path, *fragments):
    """Importing path stops with a message holding every fragment; nothing is created."""
    before = data_counts()
    try:
        bpy.ops.import_scene.gltf(filepath=path)
    except BaseException as error:  # the operator's RuntimeError carrying ImportRefused's message
        message = str(error)
    else:
        raise AssertionError("%s imported; expected a refusal with %s" % (path, fragments))
    common.check("ImportRefused" in message, "%s: not Skinpack's refusal: %s" % (path, message))
    for fragment in (path, EXTENSION.split("_")[0].capitalize()) + fragments:
        common.check(fragment in message, "%s: message lacks %r: %s" % (path, fragment, message))
    common.check(data_counts() == before, "%s: the failed import created data %s -> %s" % (path, before, data_counts()))
    print("refused: %s" % [line for line in message.splitlines() if "ImportRefused" in line][-1].strip())


def meshopt_refused(args):
    """skinpack compress --meshopt files (words in a required EXT_meshopt_compression view, whose
    fallback buffer has no data): Blender's importer has no meshopt decoder and must refuse them
    naming the extension, creating nothing, never read the data-less words."""
    if not args.cli:
        print("no --cli: the --meshopt refusal is not checked")
        return
    import subprocess
    fox = os.path.join(args.shared, "assets", "Fox.glb")
    for mode in ("compact", "fallback"):
        path = os.path.join(args.out, "Fox_%s_meshopt.glb" % mode)
        subprocess.run([args.cli, "compress", fox, "-o", path, "--" + mode, "--meshopt"], check=True,
                       capture_output=True)
        common.check("EXT_meshopt_compression" in common.Glb(path).json["extensionsRequired"], path)
        before = data_counts()
        try:
            bpy.ops.import_scene.gltf(filepath=path)
        except BaseException as error:
            message = str(error)
        else:
            raise AssertionError("%s imported; Blender cannot decode its EXT_meshopt_compression words" % path)
        common.check("EXT_meshopt_compression" in message, "%s: message does not name the extension: %s"
                     % (path, message))
        common.check(data_counts() == before, "%s: the failed import created data" % path)
        print("refused: %s: %s" % (os.path.basename(path), message.strip().splitlines()[-1]))


def vertex_word(glb, vertex):
    words = glb.accessor(glb.extension()["vertices"])[vertex]
    return int(words[0]) | (int(words[1]) << 32 if len(words) > 1 else 0)


def corrupt_files(out):
    """(path, message fragments) of each broken copy."""
    cases = []

    def case(source, label, edit, *fragments):
        glb = EditableGlb(os.path.join(EXAMPLES, source + ".glb"))
        extra = edit(glb)
        path = glb.write(os.path.join(out, "%s_%s.glb" % (source, label)))
        cases.append((path, fragments + tuple(extra or ())))

    # Fixed K = 3, n = 8: code 0 decodes to q = (0, 0, 0), whose sum is not the grid's 255.
    def outside_simplex(glb):
        bits = glb.extension()["weightBits"]
        tuple_index = vertex_word(glb, 3) >> bits
        glb.set_row(glb.extension()["vertices"], 3, [tuple_index << bits])
    case("meshlets_fixed", "outside_simplex", outside_simplex, "mesh", "primitive 0",
         "weight code 0 outside the simplex at vertex 3")

    # A tuple whose slots 0 and 1 both carry weight gets the same joint twice.
    def duplicate_joint(glb):
        joints, weights = expected_maps("fallback_oss")
        bits = glb.extension()["weightBits"]
        vertex = next(v for v in range(len(weights)) if weights[v][0] > 0 and weights[v][1] > 0)
        tuple_index = vertex_word(glb, vertex) >> bits
        row = list(glb.accessor(glb.extension()["tupleTable"])[tuple_index])
        row[1] = row[0]
        glb.set_row(glb.extension()["tupleTable"], tuple_index, row)
        users = [v for v in range(len(weights)) if vertex_word(glb, v) >> bits == tuple_index
                 and weights[v][0] > 0 and weights[v][1] > 0]
        return ["joint %d carries weight in slots 0 and 1" % row[0], "at vertex %d" % users[0]]
    case("fallback_oss", "duplicate_joint", duplicate_joint)

    # The packed words cover one vertex less than the primitive has.
    def short_vertices(glb):
        glb.json["accessors"][glb.extension()["vertices"]]["count"] -= 1
    case("compact_any", "short_vertices", short_vertices, "vertices: 5 packed vertices, the primitive has 6")

    # Integers a reader must check before narrowing them (tinygltf truncated them to 32 bits).
    def huge_influences(glb):
        glb.extension()["influences"] = 2 ** 32 + 3
    case("fallback_oss", "huge_influences", huge_influences, "influences: 4294967299 above the maximum 4")

    def unsafe_n(glb):
        glb.extension()["n"] = 2 ** 53 + 2
    case("fallback_oss", "unsafe_n", unsafe_n, "n: 9007199254740994 is above 2^53 and must be written as a string")

    # jointCount 3 but the node's skin lists 2 joints.
    def small_skin(glb):
        glb.json["skins"][0]["joints"] = glb.json["skins"][0]["joints"][:2]
    case("compact_any", "small_skin", small_skin, "jointCount: 3")

    # A second primitive sharing the packed words declares another maxError.
    def contradicting_share(glb):
        mesh = glb.json["meshes"][0]
        second = json.loads(json.dumps(mesh["primitives"][0]))
        second["extensions"][EXTENSION]["maxError"] = 0.5
        mesh["primitives"].append(second)
    case("compact_any", "contradicting_share", contradicting_share,
         "primitive 1: shares its vertices accessor with mesh", "declares other properties")

    # ... or the same parameters with another tuple table.
    def other_table_share(glb):
        mesh = glb.json["meshes"][0]
        second = json.loads(json.dumps(mesh["primitives"][0]))
        accessors = glb.json["accessors"]
        accessors.append(dict(accessors[second["extensions"][EXTENSION]["tupleTable"]]))
        second["extensions"][EXTENSION]["tupleTable"] = len(accessors) - 1
        mesh["primitives"].append(second)
    case("compact_any", "other_table_share", other_table_share,
         "primitive 1: shares its vertices accessor with mesh", "declares another tupleTable")

    # A meshlet vertex entry that points past the primitive's vertices.
    def meshlet_vertex(glb):
        glb.set_row(glb.extension()["meshlets"]["vertices"], 0, [1000])
    case("meshlets_fixed", "meshlet_vertex", meshlet_vertex, "meshlets.vertices: index 1000 not below 6")

    # Local tuple tables must be K wide (VEC3 here): a SCALAR accessor is refused by its type.
    def meshlet_tuples_type(glb):
        glb.json["accessors"][glb.extension()["meshlets"]["tuples"]]["type"] = "SCALAR"
        return ["meshlets.tuples: accessor %d is SCALAR, expected VEC3" % glb.extension()["meshlets"]["tuples"]]
    case("meshlets_fixed", "meshlet_tuples_type", meshlet_tuples_type)
    return cases


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    for name in ("fallback_oss", "compact_any", "meshlets_fixed"):
        import_valid(name)
    cases = corrupt_files(args.out)
    for path, fragments in cases:
        expect_refusal(path, *fragments)
    meshopt_refused(args)
    # A refusal leaves the importer usable.
    import_valid("compact_any")
    print("%d broken files refused" % len(cases))


common.run(main)
