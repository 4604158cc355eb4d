"""The add-on zip is an Extension for Blender 4.2+ and a legacy add-on for 3.x: one top-level
folder holding __init__.py (with bl_info) and blender_manifest.toml, the manifest has every
required key with a valid value, names the platform of the library actually inside and says why
it needs file access; the version and name agree with bl_info; the library and the layouts
generated from skinpack.h (io/_abi.py) are inside."""

import ast
import os
import sys
import tomllib
import zipfile

sys.path.insert(0, os.path.dirname(__file__))
import common  # noqa: E402

REQUIRED = ("schema_version", "id", "version", "name", "tagline", "maintainer", "type", "license",
            "blender_version_min")
ELF_PLATFORMS = {62: "linux-x64", 183: "linux-arm64"}


def main():
    args = common.arguments()
    with zipfile.ZipFile(args.zip) as archive:
        names = archive.namelist()
        tops = {name.split("/")[0] for name in names}
        common.check(tops == {"skinpack"}, "the zip must hold one top-level folder, has %s" % sorted(tops))
        manifest = tomllib.loads(archive.read("skinpack/blender_manifest.toml").decode("utf-8"))
        init = ast.parse(archive.read("skinpack/__init__.py").decode("utf-8"))
        libraries = [n for n in names if os.path.basename(n) in ("libskinpack.so", "libskinpack.dylib", "skinpack.dll")]
        common.check(libraries == ["skinpack/io/libskinpack.so"], "library in the zip: %s" % libraries)
        library = archive.read(libraries[0])
        common.check("skinpack/io/_abi.py" in names, "generated io/_abi.py missing")
    missing = [key for key in REQUIRED if key not in manifest]
    common.check(not missing, "manifest lacks %s" % missing)
    common.check(manifest["schema_version"] == "1.0.0" and manifest["type"] == "add-on", "schema/type")
    common.check(manifest["id"] == "skinpack" and manifest["id"].isidentifier(), "id %r" % manifest["id"])
    common.check(len(manifest["tagline"]) <= 64 and not manifest["tagline"].endswith("."), "tagline")
    common.check(isinstance(manifest["license"], list) and all(l.startswith("SPDX:") for l in manifest["license"]),
                 "license %r" % manifest["license"])
    common.check(tuple(int(v) for v in manifest["blender_version_min"].split(".")) >= (4, 2, 0), "blender_version_min")
    machine = int.from_bytes(library[18:20], "little")
    common.check(library[:4] == b"\x7fELF" and manifest.get("platforms") == [ELF_PLATFORMS[machine]],
                 "platforms %r for an ELF library of machine %d" % (manifest.get("platforms"), machine))
    files = manifest.get("permissions", {}).get("files", "")
    common.check(0 < len(files) <= 64, "permissions.files %r" % files)
    bl_info = next(ast.literal_eval(node.value) for node in init.body if isinstance(node, ast.Assign)
                   and any(getattr(t, "id", "") == "bl_info" for t in node.targets))
    common.check(manifest["version"] == ".".join(str(v) for v in bl_info["version"])
                 and manifest["name"] == bl_info["name"], "manifest and bl_info disagree")
    print("manifest: %s" % manifest)

    # Other platforms' libraries get their own file name and platform tag (make_zip.py).
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "addon"))
    import make_zip
    pe = bytearray(256)
    pe[:2], pe[0x3C:0x40], pe[0x80:0x84], pe[0x84:0x86] = b"MZ", (0x80).to_bytes(4, "little"), b"PE\0\0", \
        (0x8664).to_bytes(2, "little")
    macho = b"\xcf\xfa\xed\xfe" + (0x0100000C).to_bytes(4, "little") + bytes(64)
    for data, expected in ((bytes(pe), ("pe", "windows-x64")), (macho, ("macho", "macos-arm64")),
                           (b"not a library", (None, None))):
        path = os.path.join(args.out, "library.bin")
        with open(path, "wb") as handle:
            handle.write(data)
        found = make_zip.library_platform(path)
        common.check(found == expected, "%r: %s" % (expected, found))
    common.check(make_zip.LIBRARY_NAMES == {"elf": "libskinpack.so", "macho": "libskinpack.dylib",
                                            "pe": "skinpack.dll"}, "library names")


common.run(main)
