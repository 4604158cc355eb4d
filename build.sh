#!/usr/bin/env bash
# Skinpack build driver.
#   ./build.sh          install missing packages, build library, CLI and add-on zip
#   ./build.sh test     the above, then every test (also the C unit tests under ASan/UBSan and
#                       built for AArch64, run under qemu-user)
#   ./build.sh demo     the above, then the main job on the embedded default character
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
MODE=${1:-build}
JOBS=$(nproc 2>/dev/null || echo 2)

# Debian packages the build, the tests and the benchmarks need.
PACKAGES=(cmake make gcc g++ clang libclang-rt-14-dev python3-numpy blender libtinygltf-dev
          glslang-tools mesa-vulkan-drivers libvulkan-dev vulkan-tools libmeshoptimizer-dev
          gltfpack zlib1g-dev libzstd-dev zstd chromium nlohmann-json3-dev
          lld wasi-libc libclang-rt-14-dev-wasm32
          gcc-aarch64-linux-gnu g++-aarch64-linux-gnu qemu-user)

install_packages() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  # Node.js may come from another source than Debian (its npm is bundled): only add Debian's
  # packages when there is no node/npm at all.
  command -v node >/dev/null 2>&1 || missing+=(nodejs)
  command -v npm >/dev/null 2>&1 || missing+=(npm)
  if [ ${#missing[@]} -gt 0 ]; then
    echo "build.sh: installing ${missing[*]}"
    local sudo=""
    [ "$(id -u)" = 0 ] || sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  fi
  # Node tools (Khronos glTF validator), pinned by tools/package-lock.json.
  # Reinstalled whenever the lockfile is newer than what node_modules was installed from.
  if [ -f tools/package.json ] && { [ ! -f tools/node_modules/.package-lock.json ] ||
       [ tools/package-lock.json -nt tools/node_modules/.package-lock.json ]; }; then
    (cd tools && npm ci --no-audit --no-fund --loglevel=error)
  fi
  # The web runtime's packages (three, glTF-Transform, playwright-core driving Debian's chromium),
  # pinned by web/package-lock.json, the same way.
  if [ -f web/package.json ] && { [ ! -f web/node_modules/.package-lock.json ] ||
       [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; }; then
    (cd web && npm ci --no-audit --no-fund --loglevel=error)
  fi
}

build() {
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DSKINPACK_SHARED_DIR="$ROOT/../shared" >/dev/null
  cmake --build build -j "$JOBS"
  if [ -f addon/make_zip.py ]; then
    python3 addon/make_zip.py --library build/native/libskinpack.so --output build/skinpack_addon.zip
  fi
}

run_tests() {
  # Benchmarks (label bench) report numbers into docs/; they are run on purpose, not in CI.
  ctest --test-dir build --output-on-failure -j "$JOBS" -LE bench
  # The C unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DSKINPACK_SANITIZE=ON \
        -DSKINPACK_SHARED_DIR="$ROOT/../shared" >/dev/null
  cmake --build build-asan -j "$JOBS"
  ctest --test-dir build-asan --output-on-failure -j "$JOBS" -L unit
  # And built for AArch64 (the add-on on ARM Linux and Apple silicon: scalar paths, another long
  # double, FMA everywhere) with Debian's cross compiler, run under qemu-user.
  cmake -S . -B build-aarch64 -DCMAKE_TOOLCHAIN_FILE="$ROOT/cmake/aarch64-linux-gnu.cmake" \
        -DCMAKE_BUILD_TYPE=Release -DSKINPACK_TEST_PARTS=unit -DSKINPACK_SHARED_DIR="$ROOT/../shared" >/dev/null
  cmake --build build-aarch64 -j "$JOBS"
  ctest --test-dir build-aarch64 --output-on-failure -j "$JOBS" -L unit
}

install_packages
build
case "$MODE" in
  build) ;;
  test) run_tests ;;
  demo) bash scripts/demo.sh ;;
  *) echo "usage: ./build.sh [build|test|demo]" >&2; exit 2 ;;
esac
