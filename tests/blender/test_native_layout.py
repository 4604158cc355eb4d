"""The ctypes mirror of skinpack.h matches the C layout, and the binding round-trips a skin.

The C side is printed by skinpack_struct_layout (sizeof/offsetof as the compiler sees them, a
program generated from skinpack.h); the ctypes side is built from the add-on's generated
_abi.py. Any drift in field order, type or count fails here before it can corrupt a call.
"""

import ctypes
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import numpy as np  # noqa: E402


def check_mirrors(native, layout_program):
    """The ctypes mirrors have the C structs' sizes, field order and offsets."""
    layout = json.loads(subprocess.check_output([layout_program], text=True))
    for c_name, mirror in native.MIRRORED_STRUCTS.items():
        c_struct = layout[c_name]
        common.check(ctypes.sizeof(mirror) == c_struct["size"],
                     "%s: ctypes size %d, C size %d" % (c_name, ctypes.sizeof(mirror), c_struct["size"]))
        fields = [name for name, _ in mirror._fields_]
        common.check(fields == list(c_struct["fields"]), "%s: field order %s vs C %s"
                     % (c_name, fields, list(c_struct["fields"])))
        for name in fields:
            offset = getattr(mirror, name).offset
            common.check(offset == c_struct["fields"][name], "%s.%s: ctypes offset %d, C offset %d"
                         % (c_name, name, offset, c_struct["fields"][name]))


def check_abi_and_defaults(native):
    """The load-time ABI check: the mirrors' sizes pass, one wrong size is refused by the library;
    defaults come from the library, not from Python."""
    sizes = native._struct_sizes()
    lib = native.load()
    bad = ctypes.c_uint32(0)
    common.check(lib.sp_check_abi(native.SP_VERSION, (ctypes.c_size_t * len(sizes))(*sizes), len(sizes),
                                  ctypes.byref(bad)) == native.SP_OK, "sp_check_abi refuses the mirrors")
    sizes[1] += 8
    common.check(lib.sp_check_abi(native.SP_VERSION, (ctypes.c_size_t * len(sizes))(*sizes), len(sizes),
                                  ctypes.byref(bad)) != native.SP_OK and bad.value == 1, "a wrong size passed")
    common.check(lib.sp_check_abi(native.SP_VERSION + 1, None, 0, ctypes.byref(bad)) != native.SP_OK,
                 "another version passed")
    options = native.default_options()
    common.check(native.METHODS[options.method] == "oss" and options.max_influences == 4
                 and options.vertex_bits == 32 and options.merge_dont_care == 1,
                 "unexpected defaults from sp_compress_options_default")


def random_skin(vertex_count, joint_count):
    rng = np.random.default_rng(7)
    joints = np.stack([rng.choice(joint_count, 4, replace=False) for _ in range(vertex_count)]).astype(np.uint16)
    weights = rng.random((vertex_count, 4)).astype(np.float32) ** 3
    weights /= weights.sum(axis=1, keepdims=True)
    return joints, weights


def check_compress_every_method(native):
    """A random skin through compress and decompress: the decoded weights are within the
    codec's bound of the prepared (sorted, normalised) input, for every method."""
    vertex_count, joint_count = 5000, 40
    joints, weights = random_skin(vertex_count, joint_count)
    for method in native.METHODS:
        compressed = native.compress(joints, weights, joint_count, native.make_options(method, 4, vertex_bits=48))
        skin = compressed.skin
        common.check(skin.vertex_count == vertex_count and skin.influences == 4, method + ": counts")
        common.check(skin.tuple_bits + skin.weight_bits <= 48, method + ": budget exceeded")
        common.check(0 < skin.quantization.max_error <= skin.codec.max_error + 1e-6,
                     "%s: max error %g vs bound %g" % (method, skin.quantization.max_error, skin.codec.max_error))
        decoded_joints, decoded_weights = compressed.decode()
        order = np.argsort(-weights, axis=1, kind="stable")
        reference = np.take_along_axis(weights, order, axis=1)
        reference_joints = np.take_along_axis(joints, order, axis=1)
        error = np.abs(decoded_weights - reference).max(axis=1)
        common.check(np.allclose(error, compressed.per_vertex_error, atol=2e-6),
                     method + ": library per-vertex error disagrees with decode")
        significant = decoded_weights > 0
        common.check((decoded_joints[significant] == reference_joints[significant]).all(), method + ": joints")


def check_meshlets(native):
    """Meshlets: the library's defaults, and a limit error that names its triangle. Three
    triangles whose vertices use one joint each."""
    options = native.meshlet_options()
    common.check((native.MESHLET_BUILDERS[options.builder], options.max_vertices, options.max_triangles,
                  options.max_joints) == ("skin", 64, 124, 32), "unexpected defaults from sp_meshlet_options_default")
    positions = np.array([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (2, 1, 0)], dtype=np.float32)
    indices = np.array([(0, 1, 2), (2, 1, 3), (3, 1, 4)], dtype=np.uint32)
    mesh_joints, mesh_weights = native.prepare_influences(np.array([[0], [1], [2], [3], [4]]),
                                                          np.ones((5, 1), dtype=np.float32), 5, 4)
    for builder in native.MESHLET_BUILDERS:
        built = native.build_meshlets(indices, positions, mesh_joints, mesh_weights,
                                      native.meshlet_options(builder, max_joints=4))
        stats = native.meshlet_stats_dict(built.stats)
        common.check(stats["triangle_count"] == 3 and stats["max_joints"] <= 4
                     and int(built.meshlets["triangle_count"].sum()) == 3
                     and (np.bincount(built.triangle_meshlet, minlength=len(built.meshlets))
                          == built.meshlets["triangle_count"]).all(), builder + ": meshlets of three triangles")
    try:
        native.build_meshlets(indices, positions, mesh_joints, mesh_weights, native.meshlet_options(max_joints=2))
    except native.MeshletError as error:
        common.check(error.code == native.SP_ERR_LIMIT_EXCEEDED and error.triangle == 0, "error %r" % error)
    else:
        raise AssertionError("a 3-joint triangle fitted a palette of 2")


def check_error_names_vertex(native):
    """Errors come back as SkinpackError naming the vertex, not as a crash."""
    joint_count = 40
    joints, weights = random_skin(5000, joint_count)
    bad = weights.copy()
    bad[123, 0] = np.nan
    try:
        native.compress(joints, bad, joint_count, native.make_options("oss", 4, vertex_bits=32))
    except native.SkinpackError as error:
        common.check(error.code == native.SP_ERR_NONFINITE_WEIGHT and error.vertex == 123, "error %r" % error)
    else:
        raise AssertionError("NaN weight accepted")


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack.io import native
    common.check(native.load() is not None, "library did not load: %s" % native.load_error())
    check_mirrors(native, args.layout)
    check_abi_and_defaults(native)
    check_compress_every_method(native)
    check_meshlets(native)
    check_error_names_vertex(native)


common.run(main)
