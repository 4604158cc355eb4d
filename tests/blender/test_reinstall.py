"""Reinstalling or updating the add-on zip while the library is loaded crashes nothing: in this
session (same build, then a different build, then an add-on reload) and in a second Blender
that holds the library while this one reinstalls. The library is loaded from a content-named
private copy that no install writes to."""

import hashlib
import os
import shutil
import subprocess
import sys
import time
import zipfile

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

import addon_utils  # noqa: E402
import bpy  # noqa: E402

WAIT_SECONDS = 120


def digest(path):
    with open(path, "rb") as handle:
        return hashlib.sha256(handle.read()).hexdigest()


def compress_cylinder(args):
    obj = common.open_asset(args, "skinned_cylinder.blend", "Cylinder")
    common.check(bpy.ops.skinpack.compress() == {'FINISHED'}, "compress failed")
    return obj


def rebuilt_zip(args, path):
    """The same add-on with a library of different content (a trailing byte: still loadable)."""
    with zipfile.ZipFile(args.zip) as source, zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as target:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename.endswith(".so"):
                data += b"\0"
            target.writestr(item, data)
    return path


def wait_for(path, child):
    deadline = time.time() + WAIT_SECONDS
    while not os.path.exists(path):
        common.check(child.poll() is None, "the second Blender exited early (%s)" % child.returncode)
        common.check(time.time() < deadline, "timed out waiting for %s" % path)
        time.sleep(0.2)


def addon_folder():
    return os.path.join(os.environ["BLENDER_USER_SCRIPTS"], "addons", "skinpack")


def main():
    args = common.arguments()
    common.install_addon(args.zip)
    from skinpack.io import native
    compress_cylinder(args)
    first = native.loaded_path()
    first_digest = digest(first)
    common.check(not os.path.realpath(first).startswith(os.path.realpath(addon_folder()) + os.sep),
                 "the library is loaded from the add-on folder an install overwrites: %s" % first)
    common.check(os.path.basename(first).startswith("libskinpack-"), "not a content-named copy: %s" % first)

    # A second Blender loads the installed add-on and keeps the library mapped meanwhile.
    ready, go = os.path.join(args.out, "holder_ready"), os.path.join(args.out, "holder_go")
    for path in (ready, go):
        if os.path.exists(path):
            os.remove(path)
    child = subprocess.Popen([bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                              "--python", __file__, "--", "--zip", args.zip, "--shared", args.shared,
                              "--out", args.out, "--hold", ready, go],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        wait_for(ready, child)

        # Same session: the same zip again, then a different build, each while loaded.
        bpy.ops.preferences.addon_install(filepath=args.zip, overwrite=True)
        compress_cylinder(args)
        updated = rebuilt_zip(args, os.path.join(args.out, "skinpack_rebuilt.zip"))
        bpy.ops.preferences.addon_install(filepath=updated, overwrite=True)
        compress_cylinder(args)
        common.check(digest(first) == first_digest, "the loaded library file was rewritten by an install")

        # Reload (disable, enable): the new files and the new library copy, the old one untouched.
        addon_utils.disable("skinpack", default_set=True)
        addon_utils.enable("skinpack", default_set=True, handle_error=common._raise)
        # The modules the add-on itself uses now (not a fresh import by this test).
        reloaded = sys.modules["skinpack"].operators.native
        common.check(reloaded is sys.modules["skinpack.io.native"] and reloaded is not native,
                     "the re-enabled add-on still runs the old modules")
        compress_cylinder(args)
        second = reloaded.loaded_path()
        common.check(second != first and os.path.isfile(first) and digest(first) == first_digest,
                     "after the update: loaded %s, first copy %s" % (second, first))
    finally:
        open(go, "w").close()
    output, _ = child.communicate(timeout=WAIT_SECONDS)
    print(output[-2000:])
    common.check(child.returncode == 0 and "HOLDER PASSED" in output,
                 "the second Blender crashed or failed after the reinstall (exit %s)" % child.returncode)


def holder_main(ready, go):
    """The second Blender: library loaded, waits while the first one reinstalls, compresses again."""
    args = common.arguments()
    addon_utils.enable("io_scene_gltf2", default_set=True)
    common.check(addon_utils.enable("skinpack", default_set=True, handle_error=common._raise) is not None,
                 "skinpack did not enable in the second Blender")
    from skinpack.io import native
    compress_cylinder(args)
    loaded = native.loaded_path()
    before = digest(loaded)
    open(ready, "w").close()
    deadline = time.time() + WAIT_SECONDS
    while not os.path.exists(go):
        common.check(time.time() < deadline, "timed out waiting for the reinstall")
        time.sleep(0.2)
    compress_cylinder(args)
    common.check(digest(loaded) == before, "the library this Blender loaded was rewritten")
    print("HOLDER PASSED")


if "--hold" in sys.argv:
    at = sys.argv.index("--hold")
    holder_ready, holder_go = sys.argv[at + 1], sys.argv[at + 2]
    del sys.argv[at:at + 3]
    common.run(lambda: holder_main(holder_ready, holder_go))
else:
    shutil.rmtree(os.path.join(os.environ.get("BLENDER_USER_DATAFILES", "/nonexistent"), "skinpack"),
                  ignore_errors=True)
    common.run(main)
