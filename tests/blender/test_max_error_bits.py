"""A max-error budget gets the library's bits: the add-on's Compress (Max Influences left at 4)
on meshes with 1, 2, 3 and 4 influences a vertex picks the weight bits of
sp_codec_from_max_error for the K it keeps, for every method, and so does `skinpack compress
--max-error` on the same meshes exported as plain glTF (one search, in the library: neither
may size the codec for 4 influences when fewer are left)."""

import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402

EXTENSION = "SKINPACK_packed_skin"
TARGETS = (0.02, 4e-4, 3e-6)


def cli_compress(args, plain_path, method, max_error):
    out = plain_path.replace(".glb", "_%s_%g.glb" % (method, max_error))
    run = subprocess.run([args.cli, "compress", plain_path, "-o", out, "--method", method, "--max-error",
                          repr(max_error)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return run, out


def cli_refuses(args, plain_path, method, max_error):
    run, _ = cli_compress(args, plain_path, method, max_error)
    return run.returncode != 0 and "Error" in run.stderr or "error" in run.stderr


def cli_weight_bits(args, plain_path, method, max_error):
    run, out = cli_compress(args, plain_path, method, max_error)
    common.check(run.returncode == 0, "skinpack compress --method %s --max-error %g failed: %s"
                 % (method, max_error, run.stderr))
    ((_, _, primitive),) = list(common.Glb(out).skinned_primitives())
    extension = primitive["extensions"][EXTENSION]
    return extension["influences"], extension["weightBits"]


def compare(args, obj, plain_path, method, influences, max_error):
    """The add-on's Compress (and the CLI) against sp_codec_from_max_error for one target; where
    the library has no codec that meets it, both must refuse."""
    from skinpack.io import native, storage
    label = "K = %d, %s, max error %g" % (influences, method, max_error)
    obj.data.skinpack.method, obj.data.skinpack.budget = method.upper(), 'ERROR'
    obj.data.skinpack.max_error = max_error
    try:
        codec = native.codec_from_max_error(method, influences, max_error)
    except native.SkinpackError as error:
        try:
            bpy.ops.skinpack.compress()
        except RuntimeError as refusal:
            common.check(obj.name in str(refusal), "%s: refusal does not name %s: %s" % (label, obj.name, refusal))
            if plain_path:
                common.check(cli_refuses(args, plain_path, method, max_error), "%s: the CLI compressed where the "
                             "library has no codec" % label)
            print("%s: library (%s) and add-on refuse" % (label, error))
            return
        raise AssertionError("%s: the add-on compressed where the library has no codec (%s)" % (label, error))
    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "%s: compress refused" % label)
    stats = storage.load_result(obj.data).stats
    common.check(stats["influences"] == influences, "%s: the add-on kept %d influences" % (label, stats["influences"]))
    common.check(stats["weight_bits"] == codec.bits and stats["error_bound"] == codec.max_error,
                 "%s: the add-on chose %d weight bits (bound %g), the library %d (bound %g)"
                 % (label, stats["weight_bits"], stats["error_bound"], codec.bits, codec.max_error))
    common.check(codec.max_error <= max_error, "%s: bound %g above the target" % (label, codec.max_error))
    if plain_path:
        cli_k, cli_bits = cli_weight_bits(args, plain_path, method, max_error)
        common.check((cli_k, cli_bits) == (influences, codec.bits), "%s: the CLI chose K = %d and %d weight bits, "
                     "the library %d" % (label, cli_k, cli_bits, codec.bits))


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    common.install_addon(args.zip)
    from skinpack.io import native
    compared = 0
    for influences in (1, 2, 3, 4):
        obj = common.rigged_grid("K%d" % influences, 6, influences)
        common.check(obj.data.skinpack.max_influences == native.SP_MAX_INFLUENCES, "max influences not the default")
        plain_path = None
        if args.cli:
            plain_path = os.path.join(args.out, "K%d_plain.glb" % influences)
            common.make_active(obj)
            obj.find_armature().select_set(True)
            bpy.ops.export_scene.gltf(filepath=plain_path, export_format='GLB', use_selection=True)
        common.make_active(obj)
        for method in native.METHODS:
            for max_error in TARGETS:
                compare(args, obj, plain_path, method, influences, max_error)
                compared += 1
        print("K = %d: add-on%s and library agree for %d methods x %d targets"
              % (influences, " and CLI" if plain_path else "", len(native.METHODS), len(TARGETS)))
    print("%d max-error choices compared" % compared)


common.run(main)
