#!/usr/bin/env python3
"""Instructions the shaders execute on lavapipe, counted under callgrind: a figure that does not
depend on the machine's load, for comparing two builds of a pass on a shared, noisy CPU machine.

llvmpipe compiles each compute pipeline to machine code at run time; that code has no symbols, so
callgrind files it under functions named by address. Their self cost, summed over all threads, is
what the shaders executed (the compile itself, the host code and the synthetic scene's renderer are
named functions and are left out; a few unnamed loader stubs are counted too: `fgsr --help` gives
53 of them, under 0.1 M instructions together). Two runs of one binary on the same command agree to about 1e-5.

It is a count of x86 instructions, not time: a change that saves memory traffic but no instructions
shows nothing here, and one that saves instructions in a memory-bound pass may not save time. Use it
next to alternated timing rounds (`fgsr bench`), not instead of them. Needs Debian's valgrind
package (valgrind, callgrind_annotate); the quick start does not install it.

    shader_instructions.py [--jobs 2] -- BINARY [BINARY...] -- fgsr-arguments...

runs `BINARY fgsr-arguments` under callgrind for each binary (in parallel, --jobs at a time; about
100x slower than natively, most of it compiling the pipelines: `eval --frames 2` on a 480x270 capture
takes minutes), prints each one's total and its ten largest shader functions, and each total over the
first binary's.
"""
import argparse
import glob
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

JIT = re.compile(r"^\s*([\d,]+)\s+\(\s*[\d.]+%\)\s+\?\?\?:(0x[0-9a-f]+) \[\?\?\?\]")


def shader_costs(out_prefix):
    """Self cost (Ir) of each symbol-less function of one callgrind run, summed over its threads."""
    costs = {}
    for path in sorted(glob.glob(out_prefix + "*")):
        if os.path.getsize(path) == 0:
            continue
        text = subprocess.run(["callgrind_annotate", "--threshold=100", path], capture_output=True,
                              text=True, check=True).stdout
        for m in filter(None, map(JIT.match, text.splitlines())):
            costs[m.group(2)] = costs.get(m.group(2), 0) + int(m.group(1).replace(",", ""))
    return list(costs.values())


def run_one(binary, args, workdir, results, index):
    prefix = os.path.join(workdir, f"cg{index}.out")
    log = open(os.path.join(workdir, f"cg{index}.log"), "w")
    cmd = ["valgrind", "--tool=callgrind", "--separate-threads=yes", "--smc-check=all-non-file",
           f"--callgrind-out-file={prefix}.%p", binary] + args
    rc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=log).returncode
    results[index] = (rc, shader_costs(prefix) if rc == 0 else [])


def main():
    argv = sys.argv[1:]
    if argv.count("--") != 2:
        sys.exit("usage: shader_instructions.py [--jobs N] -- BINARY [BINARY...] -- fgsr-arguments...")
    first = argv.index("--")
    second = argv.index("--", first + 1)
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=2)
    opts = ap.parse_args(argv[:first])
    binaries, args = argv[first + 1:second], argv[second + 1:]
    if not binaries or not args:
        sys.exit("need at least one binary and the arguments to run it with")
    workdir = tempfile.mkdtemp(prefix="shader-instructions-")
    results = [None] * len(binaries)
    pending = list(range(len(binaries)))
    running = []
    start = last = time.time()
    while pending or running:
        while pending and len(running) < opts.jobs:
            i = pending.pop(0)
            t = threading.Thread(target=run_one, args=(binaries[i], args, workdir, results, i))
            t.start()
            running.append(t)
        time.sleep(1)
        running = [t for t in running if t.is_alive()]
        done = sum(r is not None for r in results)
        if time.time() - last >= 30 or (not pending and not running):
            print(f"[{time.time() - start:5.0f} s] {done} of {len(binaries)} runs done", file=sys.stderr, flush=True)
            last = time.time()
    # Ratios are to the first binary's count; none when its run failed.
    base = sum(results[0][1]) if results[0][0] == 0 and results[0][1] else None
    for binary, (rc, costs) in zip(binaries, results):
        if rc != 0:
            print(f"{binary}: exit status {rc} (log in {workdir})")
            continue
        total = sum(costs)
        ratio = f"{total / base:.4f} of the first" if base else "the first run failed: no ratio"
        top = ", ".join(f"{c / 1e6:.1f}" for c in sorted(costs, reverse=True)[:10])
        print(f"{binary}: {total / 1e6:.1f} M shader instructions ({ratio}); "
              f"{len(costs)} functions, largest (M): {top}")
    print(f"callgrind files: {workdir}")


if __name__ == "__main__":
    main()
