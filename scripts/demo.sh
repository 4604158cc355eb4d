#!/usr/bin/env bash
# The README's main command (./build.sh demo): the Blender demo on a character the script builds
# itself, headless, no GPU. Needs the build (build/skinpack_addon.zip, libskinpack inside).
#   SKINPACK_BUILD=build-x bash scripts/demo.sh    to use another build folder
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SKINPACK_BUILD:-build}
ZIP=$BUILD/skinpack_addon.zip
OUT=${SKINPACK_DEMO_OUT:-out/demo}
if [ ! -f "$ZIP" ]; then
  echo "demo.sh: $ZIP is missing; run ./build.sh first" >&2
  exit 1
fi
mkdir -p "$OUT"
# A scratch Blender user folder: the demo installs the add-on there, never into ~/.config.
SCRATCH=$(mktemp -d)
trap 'rm -rf "$SCRATCH"' EXIT
export BLENDER_USER_SCRIPTS=$SCRATCH/scripts BLENDER_USER_CONFIG=$SCRATCH/config BLENDER_USER_DATAFILES=$SCRATCH/datafiles
blender -b --factory-startup --python-exit-code 1 --python scripts/demo.py -- \
  --zip "$ZIP" --out "$OUT" --validator tools/validate.mjs --cli "$BUILD/native/cli/skinpack" \
  2>&1 | grep -v -e "^$" -e "| INFO:" -e "Draco mesh compression" -e "EGL Error"
