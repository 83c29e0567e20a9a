#!/usr/bin/python3
"""render --denoise (Open Image Denoise, loaded at run time).
Always: a QUALITY that is not fast, balanced or high is refused, and a library that cannot be
loaded (CANDELA_OIDN_LIBRARY naming a missing file) is one error line before the render, exit 1.
Where the library loads (scripts/setup.sh installs it; else the rest is skipped, exit 77):
- the Cornell box at 4 spp, denoised, is at least 3 times closer (relMSE) to a 1024-spp render
  than the 4-spp image itself;
- the EXR's noisy.R/G/B equal the RGB of the same render without --denoise (with and without
  the AOVs), bit for bit, and its RGB differ from them; the PNG shows the denoised image;
- merge of two denoised shards reads their unbiased estimates: it equals the merge of the same
  shards rendered without --denoise, bit for bit;
- --transparent: the alpha is the one without --denoise;
- a render interrupted between passes is denoised too.
Usage: denoise_test.py path/to/candela repo_root
"""
import os
import sys
import tempfile

import numpy as np
from candela_test_util import SKIP, check, failures, finish, read_channels as read, run


def rgb(channels, prefix=''):
    return np.stack([channels[prefix + c] for c in 'RGB'], axis=-1).astype(np.float64)


def rel_mse(x, ref):
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + 0.01)))


def main():
    candela, root = os.path.abspath(sys.argv[1]), sys.argv[2]
    scene = os.path.join(root, 'scenes', 'cornell-box', 'cornell-box.gltf')
    device = os.environ.get('CANDELA_TEST_DEVICE', 'pocl')

    def render(out, *options, env=None, size=64, seed='3'):
        cmd = [candela, 'render', scene, '--width', str(size), '--height', str(size), '--device', device, '--seed', seed,
               *sum((['-o', o] for o in (out if isinstance(out, list) else [out])), []), *options]
        return run(cmd, env={**os.environ, **(env or {})})

    with tempfile.TemporaryDirectory() as tmp:
        def at(name):
            return os.path.join(tmp, name)

        r = render(at('q.png'), '--spp', '1', '--denoise=best', '-q')
        check(r.returncode == 1 and r.stderr == "candela: error: --denoise must be fast, balanced or high, not 'best'\n",
              f'--denoise=best is refused in one line: {r.stderr.strip()}')
        r = render(at('m.png'), '--spp', '1', '--denoise', env={'CANDELA_OIDN_LIBRARY': at('no-such-lib.so')})
        lines = r.stderr.strip().split('\n')
        check(r.returncode == 1 and len(lines) == 1 and
              lines[0].startswith('candela: error: --denoise needs Open Image Denoise: ') and
              lines[0].endswith('(run scripts/setup.sh)') and 'no-such-lib.so' in lines[0],
              f'a library that cannot be loaded is one error line before the render: {r.stderr.strip()}')
        check(not os.path.exists(at('m.png')), 'and nothing is written')

        r = render(at('probe.png'), '--spp', '1', '--denoise=fast', '-q', size=8)
        if 'needs Open Image Denoise' in r.stderr:
            print('skip: Open Image Denoise is not installed (scripts/setup.sh installs it into build/oidn): '
                  + r.stderr.strip())
            sys.exit(1 if failures else SKIP)
        check(r.returncode == 0, f'a render with --denoise=fast runs: {r.stderr.strip()}')

        ref = render(at('ref.exr'), '--spp', '1024', '-q', seed='11')
        noisy = render(at('noisy.exr'), '--spp', '4', '-q', '--aov', 'albedo,normal')
        den = render([at('den.exr'), at('den.png')], '--spp', '4', '--denoise')
        check(ref.returncode == 0 and noisy.returncode == 0 and den.returncode == 0, 'the renders run')
        if failures:
            sys.exit(1)
        check('denoised in ' in den.stderr, 'the denoise time is on stderr')
        reference, plain, denoised = read(at('ref.exr')), read(at('noisy.exr')), read(at('den.exr'))
        e_noisy, e_den = rel_mse(rgb(plain), rgb(reference)), rel_mse(rgb(denoised), rgb(reference))
        check(e_den * 3 <= e_noisy, f'denoised 4 spp: relMSE {e_den:.3g} against the noisy {e_noisy:.3g} '
              f'({e_noisy / e_den:.1f}x lower; at least 3x)')
        check(all(np.array_equal(denoised['noisy.' + c], plain[c]) for c in 'RGB'),
              'the EXR\'s noisy.R/G/B are the image without --denoise, bit for bit')
        check(not np.array_equal(rgb(denoised), rgb(plain)), 'and its RGB is the denoised image')
        check(all(np.array_equal(denoised[k], plain[k]) for k in plain if k.startswith(('albedo.', 'normal.'))),
              'the guides are the AOVs albedo and normal')
        out = render([at('plain.png'), at('plain.exr')], '--spp', '4', '-q')
        check(out.returncode == 0 and all(np.array_equal(denoised['noisy.' + c], read(at('plain.exr'))[c]) for c in 'RGB'),
              'and the image of a render without AOVs, bit for bit')
        check(not np.array_equal(rgb(read(at('den.png'))), rgb(read(at('plain.png')))), 'the PNG shows the denoised image')

        for name, extra in (('d', ['--denoise=fast']), ('p', ['--aov', 'albedo,normal'])):
            for k in (0, 1):
                render(at(f'{name}{k}.exr'), '--spp', '2', '--sample-offset', str(2 * k), '-q', *extra, size=16)
            run([candela, 'merge', at(f'{name}0.exr'), at(f'{name}1.exr'), '-o', at(f'{name}.exr'), '-q'])
        check(os.path.exists(at('d.exr')) and os.path.exists(at('p.exr')) and
              np.array_equal(rgb(read(at('d.exr'))), rgb(read(at('p.exr')))),
              'merge of denoised shards equals the merge of the same shards without --denoise')

        render(at('ta.exr'), '--spp', '2', '-q', '--transparent', size=16)
        render(at('td.exr'), '--spp', '2', '-q', '--transparent', '--denoise=fast', size=16)
        check(os.path.exists(at('td.exr')) and np.array_equal(read(at('ta.exr'))['A'], read(at('td.exr'))['A']),
              '--transparent --denoise keeps the alpha')

        r = render(at('int.exr'), '--spp', '64', '--denoise=fast', env={'CANDELA_RAISE_AT': 'later-pass:INT'}, size=16)
        check(r.returncode == 130 and 'denoised in ' in r.stderr and 'noisy.R' in read(at('int.exr')),
              f'an interrupted render is denoised too (exit {r.returncode})')
    finish()
    print('all passed')


if __name__ == '__main__':
    main()
