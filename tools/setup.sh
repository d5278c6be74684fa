#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (run as root, or with the packages already there):
#   tools/setup.sh demo   install what is missing, build, run the main job on the built-in capture
#   tools/setup.sh test   install what is missing, build with warnings as errors, run the test suite
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config git glslang-tools spirv-tools libvulkan-dev mesa-vulkan-drivers
          vulkan-validationlayers libopenexr-dev libpng-dev libglm-dev nlohmann-json3-dev libcli11-dev libfmt-dev
          libgtest-dev libusb-1.0-0-dev gnuplot-nox)

install_missing() {
    local missing=()
    for p in "${packages[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if [ ${#missing[@]} -eq 0 ]; then return; fi
    echo "setup: installing ${missing[*]}" >&2
    local sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
    local preset=$1
    cmake --preset "$preset" >/dev/null
    cmake --build --preset "$preset" -j"$(nproc)"
}

case "${1:-}" in
demo)
    install_missing
    build release
    echo "setup: fgsr eval on the built-in synthetic capture (interpolation, then extrapolation) -> out/" >&2
    build/bin/fgsr eval --capture builtin --mode interp --out out/interp
    build/bin/fgsr eval --capture builtin --mode extrap --out out/extrap
    ;;
test)
    install_missing
    build ci
    ctest --preset ci -j"$(nproc)"
    ;;
*)
    echo "usage: $0 demo|test" >&2
    exit 2
    ;;
esac
