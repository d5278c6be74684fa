#!/usr/bin/env bash
# One entry point for a fresh Debian 12 machine (run as root, or with the packages already there):
#   tools/setup.sh demo   install what is missing, build, start fgsrd and replay the built-in capture
#                         through it (outputs, telemetry and metrics under out/)
#   tools/setup.sh test   install what is missing, build with warnings as errors, run the test suite;
#                         then the service and client tests under ASan + UBSan and a short run of
#                         each fuzz target
#   tools/setup.sh tsan   install what is missing, then the service, client and layer tests under
#                         ThreadSanitizer (not part of `test`: docs/RELIABILITY.md, "CI")
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config git glslang-tools spirv-tools libvulkan-dev mesa-vulkan-drivers
          vulkan-validationlayers libopenexr-dev libpng-dev libglm-dev nlohmann-json3-dev libcli11-dev libfmt-dev
          libgtest-dev libusb-1.0-0-dev gnuplot-nox
          # the Vulkan layer (client/layer) and its test application: TOML, XCB
          libtomlplusplus-dev libxcb1-dev
          # fgsrd's dashboard (--http): HTTP server, Prometheus text format, Chart.js (embedded at build)
          libcpp-httplib-dev prometheus-cpp-dev libjs-chart.js
          # `fgsr probe`'s tests, built with the rest: umockdev emulates USB probes at the usbfs level
          umockdev libumockdev-dev)
# Only the test suite needs these: python3-opencv runs the DIS reference (tools/reference/dis_vectors.py)
# in its test; xvfb and vulkan-tools (vkcube) run the Vulkan layer's end-to-end tests. Blender
# (tools/render) is needed by no test and is not installed here.
# clang (with its libFuzzer runtime) builds the fuzz targets (tests/fuzz, preset fuzz).
# chromium and chromium-driver load the dashboard in the dashboard's tests (headless, driven over
# WebDriver); prometheus brings promtool, which checks /metrics.
test_packages=(python3-opencv xvfb vulkan-tools clang chromium chromium-driver prometheus)

install_missing() {
    local missing=()
    for p in "${packages[@]}" "$@"; do
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

# Builds a sanitizer preset and runs its test preset, with the time of each on stderr.
sanitized() {
    local preset=$1 start=$SECONDS
    build "$preset"
    echo "setup: $preset build $((SECONDS - start)) s" >&2
    start=$SECONDS
    ctest --preset "$preset" -j"$(nproc)"
    echo "setup: $preset tests $((SECONDS - start)) s" >&2
}

case "${1:-}" in
demo)
    install_missing
    build release
    # The main job through the service: start fgsrd on a private socket, replay the built-in
    # capture through it with the client library (interpolation, then extrapolation), print the
    # telemetry summaries and metrics, stop the daemon.
    rundir=$(mktemp -d)
    sock="$rundir/fgsrd.sock"
    build/bin/fgsrd --socket "$sock" --log-level warn &
    daemon=$!
    trap 'kill "$daemon" 2>/dev/null || true; wait "$daemon" 2>/dev/null || true; rm -rf "$rundir"' EXIT
    for _ in $(seq 300); do
        [ -S "$sock" ] && break
        kill -0 "$daemon" 2>/dev/null || { echo "setup: fgsrd did not start" >&2; exit 1; }
        sleep 0.1
    done
    mkdir -p out/interp out/extrap
    echo "setup: fgsr replay of the built-in synthetic capture through fgsrd ($sock) -> out/" >&2
    build/bin/fgsr replay --capture builtin --mode interp --socket "$sock" --out out/interp \
        --telemetry out/interp/telemetry.csv
    build/bin/fgsr replay --capture builtin --mode extrap --socket "$sock" --out out/extrap \
        --telemetry out/extrap/telemetry.csv
    # The recorded runs as the dashboard's page and plots (out/*/report/index.html, *.png).
    for m in interp extrap; do
        build/bin/fgsr report "out/$m/telemetry.csv" --out "out/$m/report" --quiet
    done
    echo "setup: dashboards of the two runs: out/interp/report/index.html, out/extrap/report/index.html" >&2
    ;;
test)
    install_missing "${test_packages[@]}"
    build ci
    ctest --preset ci -j"$(nproc)"
    # The service, the client and the layer again under AddressSanitizer +
    # UndefinedBehaviorSanitizer (preset asan: fgsrd, fgsr, fgsr_tests and fgsr_layer_tests only;
    # the test preset selects the Daemon*, DaemonProcess*, Client*, StressDaemon* and Layer*
    # tests), then each fuzz target for a fixed count of inputs (docs/RELIABILITY.md, "Sanitizers
    # and fuzzing").
    sanitized asan
    start=$SECONDS
    tools/fuzz.sh --ci
    echo "setup: fuzz targets $((SECONDS - start)) s" >&2
    ;;
tsan)
    # fgsrd, fgsr, the layer and the service, client and layer tests built with -fsanitize=thread
    # (preset tsan); tests/sanitizers/tsan.supp says what it leaves out (lavapipe's LLVM and the
    # validation layer, which are not instrumented). The layer's end-to-end tests need Xvfb.
    install_missing xvfb
    sanitized tsan
    ;;
*)
    echo "usage: $0 demo|test|tsan" >&2
    exit 2
    ;;
esac
