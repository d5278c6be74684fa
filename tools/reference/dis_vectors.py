#!/usr/bin/python3
"""OpenCV DIS optical flow (MEDIUM preset) of a capture's colour: the reference that fgsr's
colour-only motion estimation has to beat (issue 12). A tool, not a runtime dependency of fgsr.

Usage:
  tools/reference/dis_vectors.py --capture DIR|builtin [--lr] --out FLOWDIR [--fgsr build/bin/fgsr]
                                 [--png-dir DIR] [--threads N] [--json]

Input frames are the ones `fgsr eval` feeds the engine, as `fgsr convert --colour-png` writes them
(this script runs it): every input of a capture with halfway ground truth (Blender fg, builtin);
frames 0, 2, 4, ... of a capture of consecutive frames (Mob-FGSR, Blender sr), renumbered 0, 1, 2.
The flow sees 8-bit grey (cv2.COLOR_BGR2GRAY) of the displayed sRGB colour.

Output contract (read by `fgsr eval --vectors-from FLOWDIR`):
  FLOWDIR/NNNN.flo for every input frame k >= 1 (NNNN = k, 4 digits, from 0001; no file for k = 0).
  Middlebury .flo as cv2.writeOpticalFlow writes it: float32 202021.25, int32 width, int32 height,
  then width*height*2 float32, rows top first, per pixel x then y, little-endian.
  flow(p) = (position in input k-1) - p of the content seen at pixel p of input k, in pixels of the
  input, x right, y down ("to previous": fgsr's internal vector convention).
Nothing else is written to FLOWDIR. The run time of the flow alone (DIS calc, per frame) is printed
on stdout (one JSON object with --json).

Needs Debian's python3-opencv (OpenCV 4.6) under /usr/bin/python3.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import cv2


def colour_pngs(fgsr, capture, lr, png_dir):
    """Runs `fgsr convert --colour-png`; returns the PNG paths of the inputs, in order."""
    if os.path.exists(os.path.join(png_dir, '0000.png')):
        raise SystemExit('dis_vectors: %s already holds colour PNGs; give an empty directory' % png_dir)
    cmd = [fgsr, 'convert', '--capture', capture, '--colour-png', '--out', png_dir]
    if lr:
        cmd.append('--lr')
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    pngs = []
    while os.path.exists(os.path.join(png_dir, '%04d.png' % len(pngs))):
        pngs.append(os.path.join(png_dir, '%04d.png' % len(pngs)))
    if len(pngs) < 2:
        raise SystemExit('dis_vectors: %s gave %d input frames, need at least 2' % (capture, len(pngs)))
    return pngs


def grey(path):
    img = cv2.imread(path, cv2.IMREAD_COLOR)
    if img is None:
        raise SystemExit('dis_vectors: cannot read ' + path)
    return cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)


def write_flows(pngs, out_dir):
    """DIS flow of input k towards input k-1 for k >= 1; returns the seconds of each calc()."""
    dis = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM)
    os.makedirs(out_dir, exist_ok=True)
    seconds = []
    prev = grey(pngs[0])
    for k in range(1, len(pngs)):
        cur = grey(pngs[k])
        if cur.shape != prev.shape:
            raise SystemExit('dis_vectors: %s is %s, %s is %s' % (pngs[k], cur.shape, pngs[k - 1], prev.shape))
        start = time.perf_counter()
        # calc(I0, I1) gives I0(p) ~ I1(p + flow(p)): I0 = input k, I1 = input k-1 -> "to previous".
        flow = dis.calc(cur, prev, None)
        seconds.append(time.perf_counter() - start)
        if not cv2.writeOpticalFlow(os.path.join(out_dir, '%04d.flo' % k), flow):
            raise SystemExit('dis_vectors: cannot write %s/%04d.flo' % (out_dir, k))
        prev = cur
    return seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--capture', required=True, help="capture directory (any layout fgsr reads) or 'builtin'")
    ap.add_argument('--lr', action='store_true', help='Mob-FGSR captures: LR_Inputs')
    ap.add_argument('--out', required=True, help='directory of the .flo files')
    ap.add_argument('--fgsr', default='build/bin/fgsr', help='the fgsr binary (default: build/bin/fgsr)')
    ap.add_argument('--png-dir', help='keep the colour PNGs here (default: a temporary directory)')
    ap.add_argument('--threads', type=int, help='cv2.setNumThreads (default: OpenCV\'s)')
    ap.add_argument('--json', action='store_true', help='print the timing as one JSON object')
    a = ap.parse_args()
    if a.threads is not None:
        cv2.setNumThreads(a.threads)
    with tempfile.TemporaryDirectory(prefix='fgsr-dis-') as tmp:
        pngs = colour_pngs(a.fgsr, a.capture, a.lr, a.png_dir or tmp)
        h, w = grey(pngs[0]).shape
        seconds = write_flows(pngs, a.out)
    ms = [s * 1e3 for s in seconds]
    report = dict(capture=a.capture, lr=a.lr, width=w, height=h, flows=len(ms), opencv=cv2.__version__,
                  threads=cv2.getNumThreads(), ms_median=statistics.median(ms), ms_mean=statistics.fmean(ms),
                  ms_min=min(ms), ms_max=max(ms))
    if a.json:
        print(json.dumps(report))
    else:
        print('dis_vectors: %d flows of %dx%d in %s, DIS medium %.1f ms per frame (median; min %.1f, max %.1f; '
              '%d OpenCV threads)' % (len(ms), w, h, a.out, report['ms_median'], report['ms_min'], report['ms_max'],
                                      report['threads']))


if __name__ == '__main__':
    sys.exit(main())
