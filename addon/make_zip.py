#!/usr/bin/env python3
"""Builds the installable add-on zip: addon/skinpack/ plus the native library beside io/native.py,
the struct layouts generated from skinpack.h (_abi.py) and blender_manifest.toml.

The zip is both a legacy add-on (bl_info in __init__.py, Blender 3.x-4.1) and an Extension
(blender_manifest.toml next to __init__.py, Blender 4.2+). Runs with any plain Python 3 (no
numpy, no Blender):
    python3 addon/make_zip.py --library build/native/libskinpack.so --output build/skinpack_addon.zip
"""

import argparse
import ast
import os
import sys
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import generate_abi  # noqa: E402

PACKAGE = "skinpack"
NATIVE_FOLDER = os.path.join(PACKAGE, "io")  # the library and _abi.py sit beside io/native.py
HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_HEADER = os.path.join(HERE, os.pardir, "native", "include", "skinpack.h")

# Library file name inside the add-on by binary format (native.py looks for the same names).
LIBRARY_NAMES = {"elf": "libskinpack.so", "macho": "libskinpack.dylib", "pe": "skinpack.dll"}
# Extension platform tags (Blender 4.2+ manifest) by format and machine.
ELF_MACHINES = {62: "linux-x64", 183: "linux-arm64"}
PE_MACHINES = {0x8664: "windows-x64", 0xAA64: "windows-arm64"}
MACHO_CPUS = {0x01000007: "macos-x64", 0x0100000C: "macos-arm64"}

MANIFEST_TAGLINE = "Compress skinning weights and export them as glTF"
MANIFEST_FILES_PERMISSION = "Export and import glTF files"


def library_platform(path):
    """(format, platform tag) of a shared library, read from its header."""
    with open(path, "rb") as handle:
        head = handle.read(4096)
    if head[:4] == b"\x7fELF":
        little = head[5] == 1
        machine = int.from_bytes(head[18:20], "little" if little else "big")
        return "elf", ELF_MACHINES.get(machine)
    if head[:4] in (b"\xcf\xfa\xed\xfe", b"\xce\xfa\xed\xfe"):
        return "macho", MACHO_CPUS.get(int.from_bytes(head[4:8], "little"))
    if head[:2] == b"MZ":
        offset = int.from_bytes(head[0x3C:0x40], "little")
        if head[offset:offset + 4] == b"PE\0\0":
            return "pe", PE_MACHINES.get(int.from_bytes(head[offset + 4:offset + 6], "little"))
    return None, None


def bl_info(source):
    """bl_info of the add-on's __init__.py, read without importing it (it imports bpy)."""
    with open(os.path.join(source, "__init__.py"), encoding="utf-8") as handle:
        tree = ast.parse(handle.read())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "bl_info" for t in node.targets):
            return ast.literal_eval(node.value)
    raise SystemExit("make_zip.py: no bl_info in %s/__init__.py" % source)


def manifest_text(info, platform):
    """blender_manifest.toml for Blender 4.2+, from bl_info (one version, one name)."""
    def quoted(value):
        return '"%s"' % str(value).replace("\\", "\\\\").replace('"', '\\"')
    lines = [
        'schema_version = "1.0.0"',
        "id = %s" % quoted(PACKAGE),
        "version = %s" % quoted(".".join(str(v) for v in info["version"])),
        "name = %s" % quoted(info["name"]),
        "tagline = %s" % quoted(MANIFEST_TAGLINE),
        "maintainer = %s" % quoted(info["author"]),
        'type = "add-on"',
        'license = ["SPDX:GPL-3.0-or-later"]',
        'blender_version_min = "4.2.0"',
        "platforms = [%s]" % quoted(platform),
        'tags = ["Import-Export", "Animation"]',
        "",
        "[permissions]",
        "files = %s" % quoted(MANIFEST_FILES_PERMISSION),
        "",
    ]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, help="the built libskinpack shared library")
    parser.add_argument("--output", required=True, help="the zip to write")
    parser.add_argument("--header", default=DEFAULT_HEADER, help="skinpack.h the struct layouts come from")
    args = parser.parse_args()

    source = os.path.join(HERE, PACKAGE)
    if not os.path.isfile(args.library):
        sys.exit("make_zip.py: library not found: %s" % args.library)
    binary_format, platform = library_platform(args.library)
    if platform is None:
        sys.exit("make_zip.py: %s is not a shared library for a platform Blender's extensions know" % args.library)
    with open(args.header, encoding="utf-8") as handle:
        abi_source = generate_abi.abi_module_source(handle.read())
    os.makedirs(os.path.dirname(os.path.abspath(args.output)) or ".", exist_ok=True)
    temporary = args.output + ".tmp"
    with zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as archive:
        for directory, subdirectories, files in os.walk(source):
            subdirectories[:] = sorted(d for d in subdirectories if d != "__pycache__")
            for name in sorted(files):
                if not name.endswith(".py") or name == "_abi.py":
                    continue
                path = os.path.join(directory, name)
                archive.write(path, os.path.join(PACKAGE, os.path.relpath(path, source)))
        archive.writestr(os.path.join(NATIVE_FOLDER, "_abi.py"), abi_source)
        archive.writestr(os.path.join(PACKAGE, "blender_manifest.toml"), manifest_text(bl_info(source), platform))
        archive.write(args.library, os.path.join(NATIVE_FOLDER, LIBRARY_NAMES[binary_format]))
    os.replace(temporary, args.output)  # never leave a half-written zip behind
    print("make_zip.py: wrote %s (%s)" % (args.output, platform))


if __name__ == "__main__":
    main()
