#!/usr/bin/python3
"""render --noise-threshold (adaptive sampling, host/render/adaptive.hpp), on PoCL:
- a value that is not a finite number above 0 (-1, 0, abc) is one `candela: error:` line, exit 1;
- the Cornell box, at most 64 spp and E = 0.1: the spp AOV is never below the first 16 samples nor above
  64, some pixels stop early, and the noisiest quarter of the pixels (by the relative error of
  an independent uniform render) gets more samples than the flattest quarter;
- the closed white furnace (every pixel exactly 1): the adaptive image's mean is 1 within 4
  standard errors (from its variance image);
- the Cornell box: the adaptive image's mean equals a uniform 256-spp render's (another seed)
  within 4 standard errors of the two (their variance images);
- without --noise-threshold the image is the same, bit for bit, as before (its stats say
  noise_threshold off), --noise-threshold with --time stops at the time, and merge refuses
  adaptive renders (their pixels hold different sample counts).
Usage: adaptive_test.py path/to/candela repo_root
"""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

failures = []


def check(ok, what):
    print(('ok    ' if ok else 'FAIL  ') + what)
    if not ok:
        failures.append(what)


def read(path):
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    inp.close()
    return {name: pixels[:, :, i].astype(np.float64) for i, name in enumerate(spec.channelnames)}


def rgb(c):
    return np.stack([c[k] for k in 'RGB'], axis=-1)


def main():
    candela, root = os.path.abspath(sys.argv[1]), sys.argv[2]
    cornell = os.path.join(root, 'scenes', 'cornell-box', 'cornell-box.gltf')
    furnace = os.path.join(root, 'scenes', 'furnace', 'closed-sphere.gltf')
    device = os.environ.get('CANDELA_TEST_DEVICE', 'pocl')

    def render(scene, out, *options, size=32):
        cmd = [candela, 'render', scene, '-o', out, '--width', str(size), '--height', str(size), '--device', device,
               '-q', *[str(o) for o in options]]
        return subprocess.run(cmd, capture_output=True, text=True)

    with tempfile.TemporaryDirectory() as tmp:
        def at(name):
            return os.path.join(tmp, name)

        for bad in ('-1', '0', 'abc'):
            r = render(cornell, at('bad.png'), '--noise-threshold', bad)
            lines = r.stderr.strip().splitlines()
            check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error:'),
                  f'--noise-threshold {bad}: one error line, exit 1 (got {r.returncode}: {r.stderr.strip()!r})')

        # Where the samples go
        r = render(cornell, at('a.exr'), '--spp', 64, '--noise-threshold', 0.1, '--aov', 'spp', '--seed', 1)
        check(r.returncode == 0, 'adaptive Cornell box renders: ' + r.stderr.strip()[-300:])
        r = render(cornell, at('u.exr'), '--spp', 64, '--seed', 2, '--variance', at('u-var.exr'))
        check(r.returncode == 0, 'uniform Cornell box renders: ' + r.stderr.strip()[-300:])
        if failures:
            return 1
        spp = read(at('a.exr'))['spp.Y']
        check(spp.min() >= 16 and spp.max() <= 64, f'spp AOV within [16, 64]: {spp.min()} to {spp.max()}')
        check((spp < 64).mean() > 0.1 and (spp == 64).any(),
              f'some pixels stop early, some go on: {100 * (spp < 64).mean():.0f} % below 64')
        u, var = rgb(read(at('u.exr'))), rgb(read(at('u-var.exr')))
        error = np.sqrt(var.mean(axis=-1) / (u.mean(axis=-1) ** 2 + 0.01))  # relative error of the mean
        lo, hi = np.quantile(error, [0.25, 0.75])
        noisy, flat = spp[error >= hi].mean(), spp[error <= lo].mean()
        check(noisy > 1.25 * flat, f'noisiest quarter {noisy:.1f} spp, flattest quarter {flat:.1f} spp')

        # Honest means
        r = render(furnace, at('f.exr'), '--spp', 128, '--noise-threshold', 0.02, '--variance', at('f-var.exr'),
                   '--seed', 3)
        check(r.returncode == 0, 'adaptive furnace renders: ' + r.stderr.strip()[-300:])
        if r.returncode == 0:
            f, fv = rgb(read(at('f.exr'))), rgb(read(at('f-var.exr')))
            se = np.sqrt(np.nan_to_num(fv, posinf=0.0).sum()) / f.size
            check(abs(f.mean() - 1.0) <= 4 * se + 1e-6, f'furnace mean {f.mean():.6f} = 1 within 4 x {se:.2g}')
        r = render(cornell, at('ref.exr'), '--spp', 256, '--seed', 4, '--variance', at('ref-var.exr'))
        ok = r.returncode == 0
        check(ok, 'uniform reference renders: ' + r.stderr.strip()[-300:])
        r = render(cornell, at('b.exr'), '--spp', 256, '--noise-threshold', 0.02, '--seed', 5, '--variance',
                   at('b-var.exr'))
        check(r.returncode == 0, 'adaptive Cornell box at 256 spp renders: ' + r.stderr.strip()[-300:])
        if ok and r.returncode == 0:
            ref, rv = rgb(read(at('ref.exr'))), rgb(read(at('ref-var.exr')))
            b, bv = rgb(read(at('b.exr'))), rgb(read(at('b-var.exr')))
            se = np.sqrt(rv.sum() + np.nan_to_num(bv, posinf=0.0).sum()) / b.size
            check(abs(b.mean() - ref.mean()) <= 4 * se,
                  f'Cornell box mean adaptive {b.mean():.5f}, uniform {ref.mean():.5f}, 4 x {se:.2g}')

        # Off by default; --time ends it
        r = render(cornell, at('d.exr'), '--spp', 4, '--seed', 6, '--stats', at('d.json'))
        r2 = render(cornell, at('d2.exr'), '--spp', 4, '--seed', 6)
        check(r.returncode == 0 and r2.returncode == 0, 'default renders')
        if r.returncode == 0:
            stats = json.load(open(at('d.json')))
            check(stats.get('noise_threshold') == 'off', f'stats noise_threshold off: {stats.get("noise_threshold")}')
            check(np.array_equal(rgb(read(at('d.exr'))), rgb(read(at('d2.exr')))), 'default render repeats bit for bit')
        r = render(cornell, at('t.exr'), '--time', 1, '--noise-threshold', 0.001, '--stats', at('t.json'),
                   '--aov', 'spp')
        check(r.returncode == 0, '--time with --noise-threshold renders: ' + r.stderr.strip()[-300:])
        if r.returncode == 0:
            stats = json.load(open(at('t.json')))
            check(stats['seconds'] < 3.0 and read(at('t.exr'))['spp.Y'].min() >= 1,
                  f'--time 1 stops after {stats["seconds"]:.2f} s with every pixel sampled')
        m = subprocess.run([candela, 'merge', at('a.exr'), at('b.exr'), '-o', at('m.exr')], capture_output=True,
                           text=True)
        check(m.returncode == 1 and m.stderr.startswith('candela: error: cannot merge'),
              'merge refuses adaptive renders: ' + m.stderr.strip())
    print('%d failure(s)' % len(failures))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
