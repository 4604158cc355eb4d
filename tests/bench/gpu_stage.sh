#!/bin/sh
# gpu_stage.sh - stages the GPU benchmark (docs/benchmarks-gpu.md) for a machine that has a GPU
# but no Blender, glslang or Vulkan loader, such as the device machine of a development session:
# a Release build of skinpack_gpu_bench, its SPIR-V, the exported meshes and the Vulkan loader
# package go into .gpu/ (git-ignored), with .gpu/run.sh to run there.
#
#   tests/bench/gpu_stage.sh                 # here: build, export, download (needs Blender, apt)
#   sh .gpu/run.sh [bench options]           # there, from the repository root
#
# With the device tool: run(command="sh .gpu/run.sh", carry=[".gpu"]). run.sh unpacks the loader
# when the machine has none, points it at the NVIDIA ICD when it finds no other, and writes the
# bench's output to $OUT/gpu_bench.txt as well when $OUT is set. Defaults are the Paper's setup:
# 1024 instances at 1920x1080, 100 frames a measurement.
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
shared=${SKINPACK_SHARED_DIR:-$root/../shared}
build=$root/build-gpu-stage
stage=$root/.gpu
assets=$shared/assets
export_mesh=$root/tests/shaders/export_skin_mesh.py

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DSKINPACK_SHARED_DIR="$shared" \
      -DSKINPACK_TEST_PARTS=shaders >/dev/null
cmake --build "$build" -j2 --target skinpack_gpu_bench skinpack_shaders >/dev/null
rm -rf "$stage"
mkdir -p "$stage/spirv" "$stage/deb"
cp "$build/tests/shaders/skinpack_gpu_bench" "$stage/"
cp "$build"/tests/shaders/spirv/*.spv "$stage/spirv/"

# The scene of docs/benchmarks-gpu.md: RE_Player, its level-1 and level-2 subdivided copies and
# the cylinder, 14.9 M skinned vertices a frame at 1024 instances.
export_one() { # blend output [export options]
    blend=$1; output=$2; shift 2
    blender -b "$assets/$blend" --factory-startup --python-exit-code 1 --python "$export_mesh" -- \
            "$@" --output "$stage/$output" >/dev/null 2>&1 || { echo "gpu_stage: export of $output failed" >&2; exit 1; }
}
export_one RE_Player_female.blend re0.spskin --object RE_Player
export_one RE_Player_female.blend re1.spskin --object RE_Player --subdivide 1 --name RE_Player_sub1
export_one RE_Player_female.blend re2.spskin --object RE_Player --subdivide 2 --name RE_Player_sub2
export_one skinned_cylinder.blend cylinder.spskin

# The Vulkan loader for the target machine (x86-64 Debian package; the NVIDIA driver there
# brings its own ICD). Fetched with a private package list so the host's apt state is untouched.
lists=$(mktemp -d)
mkdir -p "$lists/partial"
apt_options="-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=$lists"
apt-get $apt_options update >/dev/null
(cd "$stage/deb" && apt-get $apt_options download libvulkan1 >/dev/null)
rm -rf "$lists"

cat >"$stage/run.sh" <<'RUN'
#!/bin/sh
# Runs the staged GPU benchmark from the repository root (see tests/bench/gpu_stage.sh).
set -eu
if ! ldconfig -p | grep -q libvulkan.so.1; then
    for f in .gpu/deb/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ] && [ -f "$nvidia_icd" ] &&
   ! ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json >/dev/null 2>&1; then
    export VK_DRIVER_FILES="$nvidia_icd"
fi
command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || true
log=/dev/null
[ -n "${OUT:-}" ] && log="$OUT/gpu_bench.txt"
SKINPACK_SHADER_DIR=.gpu/spirv .gpu/skinpack_gpu_bench --instances 1024 --frames 100 --width 1920 --height 1080 "$@" \
    .gpu/re0.spskin .gpu/re1.spskin .gpu/re2.spskin .gpu/cylinder.spskin 2>&1 | tee "$log"
RUN
chmod +x "$stage/run.sh"
du -sh "$stage"
echo "staged in $stage; run there: sh .gpu/run.sh (carry .gpu)"
