#!/bin/sh
# fgsr probe's samples reach fgsrd: the real CLI measures an emulated probe (umockdev, through
# fgsr_probe_emulator) and sends its samples to a real fgsrd started with --http; the daemon's
# /metrics must count every one of them as click-to-photon latency.
# Usage: probe_to_fgsrd.sh BIN_DIR UMOCKDEV_WRAPPER EMULATOR
set -eu
bin=$1
wrapper=$2
emulator=$3
dir=$(mktemp -d /tmp/fgsr-probe-e2e-XXXXXX)
chmod 700 "$dir"
"$bin/fgsrd" --socket "$dir/s.sock" --http 127.0.0.1:0 --log-level info >/dev/null 2>"$dir/fgsrd.log" &
pid=$!
trap 'kill $pid 2>/dev/null || true; wait $pid 2>/dev/null || true; rm -rf "$dir"' EXIT
url=""
for _ in $(seq 300); do
    url=$(sed -n 's/.*dashboard at \(http:[^ ]*\).*/\1/p' "$dir/fgsrd.log" | head -n 1)
    [ -S "$dir/s.sock" ] && [ -n "$url" ] && break
    sleep 0.1
done
[ -n "$url" ] || { echo "fgsrd did not start:"; cat "$dir/fgsrd.log"; exit 1; }
"$wrapper" "$emulator" --gadget fgsr -- "$bin/fgsr" probe --count 12 --interval 5 --socket "$dir/s.sock" --quiet
# No reply confirms the samples: read /metrics until they are counted (at most 5 s).
for _ in $(seq 50); do
    python3 -c 'import sys, urllib.request; sys.stdout.write(urllib.request.urlopen(sys.argv[1] + "metrics").read().decode())' \
        "$url" >"$dir/metrics"
    if grep -Eq '^fgsr_click_to_photon_seconds_count\{mode="[a-z]+"\} 12$' "$dir/metrics"; then
        echo "fgsrd counted the probe's 12 samples"
        exit 0
    fi
    sleep 0.1
done
echo "fgsrd's /metrics does not count 12 click-to-photon samples:"
grep click_to_photon "$dir/metrics" || true
exit 1
