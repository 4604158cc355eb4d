#!/bin/sh
# build.sh OUT.wasm - libskinpack's decode side as WebAssembly, for web/src/wasm.js.
#
# The one recipe: the CMake target skinpack_wasm (native/wasm/CMakeLists.txt) and the web
# package's `npm run build:wasm` both run it. Needs clang with the wasm32-wasi target, wasm-ld
# and a WASI libc (Debian: clang, lld, wasi-libc, libclang-rt-14-dev-wasm32). Environment:
# WASM_CC (default clang) and WASI_SYSROOT (default /usr/share/wasi-sysroot when it exists,
# else the compiler's own: Debian's clang finds /usr/include/wasm32-wasi by itself).
#
# Sources: every library file except the x86 vector paths (platform.h compiles them out on
# wasm32 anyway) and the meshlet builders (nothing here builds meshlets; validation of stored
# meshlets is validate.c). The linker keeps only what the exports reach. -flto lets clang inline
# across the library's files (validation calls the bit unpacking and the decoders once a
# vertex): about 1.4 times the speed of -O2 alone, as fast as the native library.
set -eu
out=${1:?usage: build.sh OUT.wasm}
here=$(cd "$(dirname "$0")" && pwd)
src="$here/../src"
cc=${WASM_CC:-clang}
sysroot=${WASI_SYSROOT:-}
[ -z "$sysroot" ] && [ -d /usr/share/wasi-sysroot ] && sysroot=/usr/share/wasi-sysroot

set --
for f in "$src"/*.c; do
  case "$f" in
    *_avx2.c | *_avx512.c | */meshlets*.c) ;;
    *) set -- "$@" "$f" ;;
  esac
done

# The library functions the JS side calls directly; spw_* (skinpack_wasm.c) export themselves.
exports="malloc free sp_version sp_method_name sp_method_from_name sp_field_name sp_parse_decimal sp_joint_bytes
         sp_words_per_vertex"
flags=""
for name in $exports; do flags="$flags -Wl,--export=$name"; done

mkdir -p "$(dirname "$out")"
# -ffp-contract=off as in native/CMakeLists.txt: each operation rounds as the specification's.
# shellcheck disable=SC2086 # $flags and the sysroot option are word lists
"$cc" --target=wasm32-wasi ${sysroot:+--sysroot="$sysroot"} -std=c11 -O2 -flto -ffp-contract=off -Wall -Wextra -Werror \
  -fvisibility=hidden -I"$here/../include" -nostartfiles -Wl,--no-entry -Wl,--gc-sections $flags \
  -o "$out.tmp" "$here/skinpack_wasm.c" "$@"
mv "$out.tmp" "$out"
