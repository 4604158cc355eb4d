"""A max-error budget gets the library's bits: the add-on's Compress (Max Influences left at 4)
on meshes with 1, 2, 3 and 4 influences a vertex picks the weight bits of
sp_codec_from_max_error for the K it keeps, for every method (one search, in the library: the
add-on must not size the codec for 4 influences when fewer are left), and refuses, naming the
object, where the library has no codec that meets the target."""

import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import bpy  # noqa: E402

TARGETS = (0.02, 4e-4, 3e-6)


def compare(obj, method, influences, max_error):
    """The add-on's Compress against sp_codec_from_max_error for one target; where
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
        common.make_active(obj)
        for method in native.METHODS:
            for max_error in TARGETS:
                compare(obj, method, influences, max_error)
                compared += 1
        print("K = %d: add-on and library agree for %d methods x %d targets" % (influences, len(native.METHODS),
                                                                              len(TARGETS)))
    print("%d max-error choices compared" % compared)


common.run(main)
