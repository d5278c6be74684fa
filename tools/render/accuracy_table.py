#!/usr/bin/env python3
"""Accuracy table of issue 16: runs `fgsr eval --json` on every capture of the dev set and every mode
that applies, and prints Markdown (docs/ACCURACY.md's tables and its list of done-when comparisons).

    python3 tools/render/accuracy_table.py --fgsr build/bin/fgsr --shared ../shared/captures \
        --renders /work/data/renders --json-dir /work/data/accuracy > table.md

Captures (the split is fixed in tools/render/README.md, "The split"; never tune on validation):
  kind fg (frame generation): modes interp and extrap, methods fgsr, fgsr-colour, linear, blend, repeat;
  kind sr (super resolution): mode sr (methods fgsr, fgsr-bilinear, fgsr-bicubic, bilinear, bicubic),
    modes isr and esr (eval's default methods: the spatial columns are frame generation + upscale);
  mobfgsr-bunker: HR (default) for interp / extrap, `--lr` for sr / isr / esr.
Each eval's JSON is kept in --json-dir (CAPTURE__MODE.json); --reuse reads those instead of running
eval again. Progress goes to stderr. Comparisons use the mean PSNR (dB) over the capture's frames.
Python 3 standard library only.
"""
import argparse, json, os, subprocess, sys, time

FG_METHODS = ['fgsr', 'fgsr-colour', 'linear', 'blend', 'repeat']
SR_METHODS = ['fgsr', 'fgsr-bilinear', 'fgsr-bicubic', 'bilinear', 'bicubic']
ISR_COLUMNS = ['fgsr', 'fgsr-colour', 'fgsr-bilinear', 'fgsr-bicubic', 'bilinear', 'bicubic']
NEW_TRAIN = ['street', 'foliage', 'hdr']
NEW_VALIDATION = ['static', 'fan', 'cut']
# Train renders of kind fg only, made later to study one difficulty without tuning on its validation
# scene (tools/render/README.md, "The split"): rotor (fan), sundial (shadow), pan seed 2 (pan), twirl (spin);
# orbit (the scene of shared/captures/blender/orbit-sr, kind fg: a camera orbiting a cluster); vane,
# brickvane and slats (fan's second to fourth counterparts, 2026-12-07).
NEW_TRAIN_FG = ['rotor', 'sundial', 'pan-s2', 'twirl', 'orbit', 'vane', 'brickvane', 'slats']
# Train renders of kind sr made later still: rotor (fan-sr's counterpart, docs/ACCURACY.md change 19).
NEW_TRAIN_SR = ['rotor']
# Kind sr rendered without jitter and with antialiased lr/ (`--no-jitter --lr-spp 16`: an unjittered
# game handing over its antialiased output, as mobfgsr-bunker LR is), named SCENE-sraa; each scene
# keeps its split (docs/ACCURACY.md, change 45). foliage, hdr and shelf (a train counterpart of static,
# 2026-12-07) were added by change 47, after the first five had been measured; vane, slats and twirl
# (train scenes) after change 48.
AA_SR = [('street', 'train'), ('rotor', 'train'), ('foliage', 'train'), ('hdr', 'train'), ('shelf', 'train'),
         ('vane', 'train'), ('slats', 'train'), ('twirl', 'train'),
         ('fan', 'validation'), ('static', 'validation'), ('cut', 'validation')]


def captures(shared, renders):
    """(name, path or 'builtin', split, kind, extra eval arguments), in the order of the tables."""
    c = [('builtin', 'builtin', 'train', 'fg', []),
         ('toss-fg', os.path.join(shared, 'blender', 'toss-fg'), 'train', 'fg', []),
         ('orbit-sr', os.path.join(shared, 'blender', 'orbit-sr'), 'train', 'sr', []),
         ('mobfgsr-bunker HR', os.path.join(shared, 'mobfgsr-bunker'), 'train', 'fg', []),
         ('mobfgsr-bunker LR', os.path.join(shared, 'mobfgsr-bunker'), 'train', 'sr', ['--lr'])]
    for split, scenes in (('train', NEW_TRAIN), ('validation', NEW_VALIDATION)):
        for s in scenes:
            c.append(('%s-fg' % s, os.path.join(renders, '%s-fg' % s), split, 'fg', []))
            c.append(('%s-sr' % s, os.path.join(renders, '%s-sr' % s), split, 'sr', []))
    for s in NEW_TRAIN_FG:
        c.append(('%s-fg' % s, os.path.join(renders, '%s-fg' % s), 'train', 'fg', []))
    for s in NEW_TRAIN_SR:
        c.append(('%s-sr' % s, os.path.join(renders, '%s-sr' % s), 'train', 'sr', []))
    for s in ('pan', 'spin', 'shadow'):
        c.append(('%s-fg' % s, os.path.join(renders, '%s-fg' % s), 'validation', 'fg', []))
    for s, split in AA_SR:
        c.append(('%s-sraa' % s, os.path.join(renders, '%s-sraa' % s), split, 'sr', []))
    return c


def runs(kind):
    """(mode, methods or None for eval's default) for a capture kind."""
    if kind == 'fg':
        return [('interp', FG_METHODS), ('extrap', FG_METHODS)]
    return [('sr', SR_METHODS), ('isr', None), ('esr', None)]


def evaluate(fgsr, name, path, mode, methods, extra, json_dir, reuse):
    fn = os.path.join(json_dir, '%s__%s.json' % (name.replace(' ', '_'), mode))
    if reuse and os.path.exists(fn):
        with open(fn) as fp:
            return json.load(fp), 'cached'
    cmd = [fgsr, 'eval', '--capture', path, '--mode', mode, '--json', '--quiet'] + extra
    if methods:
        cmd += ['--methods', ','.join(methods)]
    t0 = time.time()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError('%s failed (%d): %s' % (' '.join(cmd), p.returncode, p.stderr.strip()[-500:]))
    r = json.loads(p.stdout)
    r['_command'] = ' '.join(cmd)
    os.makedirs(json_dir, exist_ok=True)
    with open(fn, 'w') as fp:
        json.dump(r, fp, indent=1)
    return r, '%.0f s' % (time.time() - t0)


def cell(m, bold=False):
    if m is None:
        return '-'
    s = '%.2f' % m['psnr']
    return ('**%s**' % s if bold else s) + ' / %.3f' % m['ssim']


def table(rows, columns):
    out = ['| capture | split | mode | size, frames | ' + ' | '.join(columns) + ' |',
           '|---|---|---|---|' + '---|' * len(columns)]
    for name, split, mode, r in rows:
        ms = r['methods']
        best = max((ms[c]['psnr'] for c in columns if c in ms), default=None)
        cells = [cell(ms.get(c), c in ms and ms[c]['psnr'] == best) for c in columns]
        size = '%dx%d, %d%s' % (r['width'], r['height'], r['frames'], ' (half rate)' if r.get('composed_vectors') else '')
        out.append('| %s | %s | %s | %s | %s |' % (name, split, mode, size, ' | '.join(cells)))
    return out


def check(rows):
    """The done-when comparisons of issue 16, per capture: (name, split, text, holds)."""
    res = []
    for name, split, mode, r in rows:
        ms = r['methods']
        if mode in ('interp', 'extrap'):
            a, b = 'fgsr', 'linear'
        elif mode in ('isr', 'esr'):
            a, b = 'fgsr', 'bicubic'
        else:
            a, b = 'fgsr', 'fgsr-bilinear'
        if a not in ms or b not in ms:
            continue
        d = ms[a]['psnr'] - ms[b]['psnr']
        res.append((name, split, '%s %s: %s %.2f vs %s %.2f dB (%+.2f)' % (name, mode, a, ms[a]['psnr'], b, ms[b]['psnr'], d), d >= 0))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--fgsr', default='build/bin/fgsr')
    ap.add_argument('--shared', default='../shared/captures', help='folder holding blender/ and mobfgsr-bunker/')
    ap.add_argument('--renders', default='../data/renders', help='folder holding SCENE-fg and SCENE-sr renders')
    ap.add_argument('--json-dir', default='accuracy-json', help='where each eval JSON is kept')
    ap.add_argument('--reuse', action='store_true', help='read kept JSON instead of running eval where present')
    ap.add_argument('--only', default='', help='comma-separated capture names to run (default: all)')
    a = ap.parse_args()
    only = set(x for x in a.only.split(',') if x)
    todo = [(c, m) for c in captures(a.shared, a.renders) if not only or c[0] in only for m in runs(c[3])]
    fg_rows, sr_rows, isr_rows, missing = [], [], [], []
    for i, ((name, path, split, kind, extra), (mode, methods)) in enumerate(todo, 1):
        if path != 'builtin' and not os.path.isdir(path):
            print('[%d/%d] %s %s: missing (%s)' % (i, len(todo), name, mode, path), file=sys.stderr)
            missing.append('%s (%s)' % (name, mode))
            continue
        print('[%d/%d] %s %s ...' % (i, len(todo), name, mode), file=sys.stderr, end='', flush=True)
        r, how = evaluate(a.fgsr, name, path, mode, methods, extra, a.json_dir, a.reuse)
        print(' %s' % how, file=sys.stderr)
        (fg_rows if kind == 'fg' else sr_rows if mode == 'sr' else isr_rows).append((name, split, mode, r))
    key = lambda row: (row[1] != 'train',)   # train first, then validation; stable otherwise
    fg_rows.sort(key=key); sr_rows.sort(key=key); isr_rows.sort(key=key)
    out = ['### Frame generation (interp, extrap; alpha 0.5)', '',
           'Mean PSNR (dB) / SSIM; the best PSNR of a row in bold.', '']
    out += table(fg_rows, FG_METHODS)
    out += ['', '### Super resolution (sr: every frame upscaled 2x)', '']
    out += table(sr_rows, SR_METHODS)
    out += ['', '### Frame generation at output resolution (isr, esr; `bilinear` / `bicubic`: frame generation, then upscale)', '']
    out += table(isr_rows, ISR_COLUMNS)
    cuts = ['%s %s: %s %d' % (n, m, k, v['scene_cuts']) for n, _, m, r in fg_rows + sr_rows + isr_rows
            for k, v in r['methods'].items() if v.get('scene_cuts')]
    if cuts:
        out += ['', 'Scene cuts detected (eval scored the nearest input in place of the refused pair): ' + '; '.join(cuts) + '.']
    devices = sorted(set(r['device'] for _, _, _, r in fg_rows + sr_rows + isr_rows))
    out += ['', 'Device (from eval): %s. Binary: `%s`.' % (', '.join(devices), a.fgsr)]
    checks = check(fg_rows + sr_rows + isr_rows)
    for split in ('train', 'validation'):
        cs = [c for c in checks if c[1] == split]
        out += ['', '### Done-when comparisons, %s: %d of %d hold' % (split, sum(c[3] for c in cs), len(cs)), '']
        out += ['- %s %s' % ('holds:' if c[3] else '**FAILS:**', c[2]) for c in cs]
    if missing:
        out += ['', 'Missing captures (not evaluated): ' + ', '.join(missing) + '.']
    print('\n'.join(out))


if __name__ == '__main__':
    main()
