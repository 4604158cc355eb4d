#!/usr/bin/env python3
"""Builds the installable add-on zip: addon/skinpack/ plus the native library beside native.py.

Runs with any plain Python 3 (no numpy, no Blender):
    python3 addon/make_zip.py --library build/native/libskinpack.so --output build/skinpack_addon.zip
"""

import argparse
import os
import sys
import zipfile

PACKAGE = "skinpack"
LIBRARY_NAME = "libskinpack.so"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, help="the built libskinpack shared library")
    parser.add_argument("--output", required=True, help="the zip to write")
    args = parser.parse_args()

    source = os.path.join(os.path.dirname(os.path.abspath(__file__)), PACKAGE)
    if not os.path.isfile(args.library):
        sys.exit("make_zip.py: library not found: %s" % args.library)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)) or ".", exist_ok=True)
    temporary = args.output + ".tmp"
    with zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as archive:
        for directory, subdirectories, files in os.walk(source):
            subdirectories[:] = sorted(d for d in subdirectories if d != "__pycache__")
            for name in sorted(files):
                if not name.endswith(".py"):
                    continue
                path = os.path.join(directory, name)
                archive.write(path, os.path.join(PACKAGE, os.path.relpath(path, source)))
        archive.write(args.library, os.path.join(PACKAGE, LIBRARY_NAME))
    os.replace(temporary, args.output)  # never leave a half-written zip behind
    print("make_zip.py: wrote %s" % args.output)


if __name__ == "__main__":
    main()
