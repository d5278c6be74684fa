#!/usr/bin/env bash
# The libFuzzer targets of tests/fuzz (preset fuzz, build-fuzz/; docs/RELIABILITY.md):
#   tools/fuzz.sh TARGET [SECONDS [OPTIONS...]]
#                                    one long run (default 600 s; OPTIONS go to libFuzzer, e.g.
#                                    -timeout=60 or -jobs=2) with its corpus in
#                                    build-fuzz/corpus/TARGET (kept between runs) and findings in
#                                    build-fuzz/findings/TARGET/; prints executions and findings
#   tools/fuzz.sh --ci [RUNS]        every target for RUNS inputs (default 20000) or 15 s, whichever
#                                    comes first, from the seeds only, as tools/setup.sh test does;
#                                    fails on any finding
#   tools/fuzz.sh --list             the targets
# Builds the fuzz preset first when needed (clang, ccache when installed). Exit status 1 when a
# target found something (the reproducer's path is printed: build-fuzz/bin/TARGET FILE replays it).
set -euo pipefail
cd "$(dirname "$0")/.."

build() {
    if [ ! -f build-fuzz/CMakeCache.txt ]; then
        local launcher=()
        if command -v ccache >/dev/null; then
            launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
        fi
        cmake --preset fuzz "${launcher[@]}" >/dev/null
    fi
    cmake --build --preset fuzz -j"$(nproc)" >/dev/null
}

# run TARGET CORPUS_DIR LOG libFuzzer-options...: one run over the corpus and the seeds.
run() {
    local target=$1 corpus=$2 log=$3
    shift 3
    local findings=build-fuzz/findings/$target
    mkdir -p "$corpus" "$findings"
    local dirs=("$corpus")
    for d in tests/fuzz/seeds/"$target" build-fuzz/seeds/"$target"; do
        [ -d "$d" ] && dirs+=("$d")
    done
    local rc=0
    build-fuzz/bin/"$target" -artifact_prefix="$findings/" -print_final_stats=1 -timeout=10 "$@" "${dirs[@]}" \
        >"$log" 2>&1 || rc=$?
    local execs rate found
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
    found=$(grep -E '^(artifact_prefix|Test unit written to)' "$log" | sed -n 's/.*Test unit written to //p' || true)
    printf 'fuzz: %-18s %10s executions %7s exec/s  corpus %s files' "$target" "${execs:-?}" "${rate:-?}" \
        "$(find "$corpus" -type f | wc -l)" >&2
    if [ "$rc" -ne 0 ]; then
        printf '  FINDING (exit %s): %s\n' "$rc" "${found:-see $log}" >&2
        grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz check failed|.*runtime error)' "$log" | head -5 >&2 || true
        return 1
    fi
    printf '  no findings\n' >&2
}

case "${1:-}" in
--list)
    build
    cat build-fuzz/fuzzers.txt
    ;;
--ci)
    runs=${2:-20000}
    build
    status=0
    mkdir -p build-fuzz/logs
    while read -r target; do
        [ -n "$target" ] || continue
        # A fresh corpus each time: CI results depend on the seeds and the fixed random seed only.
        rm -rf build-fuzz/ci-corpus/"$target"
        run "$target" build-fuzz/ci-corpus/"$target" build-fuzz/logs/"$target".ci.log -runs="$runs" -max_total_time=15 -seed=1 ||
            status=1
    done <build-fuzz/fuzzers.txt
    exit $status
    ;;
"" | -*)
    echo "usage: $0 TARGET [SECONDS] | --ci [RUNS] | --list" >&2
    exit 2
    ;;
*)
    target=$1
    seconds=${2:-600}
    shift $(($# < 2 ? $# : 2))
    build
    if ! grep -qx "$target" build-fuzz/fuzzers.txt; then
        echo "fuzz: unknown target $target (tools/fuzz.sh --list)" >&2
        exit 2
    fi
    mkdir -p build-fuzz/logs
    log=build-fuzz/logs/$target.log
    echo "fuzz: $target for $seconds s, corpus build-fuzz/corpus/$target, log $log" >&2
    run "$target" build-fuzz/corpus/"$target" "$log" -max_total_time="$seconds" "$@"
    ;;
esac
