#!/usr/bin/python3
"""Motion blur (--shutter) on real renders against the analytic shapes of the streaks.

Emissive shapes on black seen by an orthographic camera (xmag = ymag = 1): a pixel's value is
the fraction of its area and of the shutter that the shape covers.
- A 0.5-wide quad translating along x at 1 unit/s, blurred over 0.25 s (8 of the 64 pixels):
  each column's mean is the box convolved with the motion, a plateau of 1 and linear ramps
  (whose ends fall on pixel edges, so a pixel's mean is the value at its centre). The same
  streak, mirrored, when the camera moves instead; and from a frame of --frames.
- A thin bar (half-length 0.8, width 0.04) turning 90 degrees about its centre during the
  shutter: at radius r inside the swept quarter a point is covered for the bar's angular
  width 2 asin(w / 2r) out of the 90 degrees; outside the quarter nothing.
- Without --shutter the quad's edges are sharp; bad --shutter values are one error line.
On CANDELA_TEST_DEVICE (default pocl).
Usage: motion_blur_test.py path/to/candela repo_root
"""
import math
import os
import struct
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio
from candela_test_util import check, finish, run, write_gltf

DEVICE = os.environ.get('CANDELA_TEST_DEVICE', 'pocl')

def write_scene(path, pos, idx, times, path_name, values, animated_node):
    """An emissive mesh (node 0) and an orthographic camera (node 1, at z = 5 looking down
    -z, 2 units across), `animated_node`'s `path_name` keyed LINEAR at `times`."""
    width = {'translation': '<3f', 'rotation': '<4f'}[path_name]
    blobs = [b''.join(struct.pack('<3f', *p) for p in pos), b''.join(struct.pack('<H', i) for i in idx),
             b''.join(struct.pack('<f', t) for t in times), b''.join(struct.pack(width, *v) for v in values)]
    lo = [min(p[k] for p in pos) for k in range(3)]
    hi = [max(p[k] for p in pos) for k in range(3)]
    doc = {
        'asset': {'version': '2.0'}, 'scene': 0, 'scenes': [{'nodes': [0, 1]}],
        'nodes': [{'mesh': 0}, {'camera': 0, 'translation': [0, 0, 5]}],
        'cameras': [{'type': 'orthographic', 'orthographic': {'xmag': 1, 'ymag': 1, 'znear': 0.1, 'zfar': 10}}],
        # (no specular layer: the plain diffuse kernel, a short build on every device)
        'extensionsUsed': ['KHR_materials_specular'],
        'materials': [{'pbrMetallicRoughness': {'baseColorFactor': [0, 0, 0, 1], 'metallicFactor': 0},
                       'emissiveFactor': [1, 1, 1], 'doubleSided': True,
                       'extensions': {'KHR_materials_specular': {'specularFactor': 0}}}],
        'meshes': [{'primitives': [{'attributes': {'POSITION': 0}, 'indices': 1, 'material': 0}]}],
        'accessors': [
            {'bufferView': 0, 'componentType': 5126, 'count': len(pos), 'type': 'VEC3', 'min': lo, 'max': hi},
            {'bufferView': 1, 'componentType': 5123, 'count': len(idx), 'type': 'SCALAR'},
            {'bufferView': 2, 'componentType': 5126, 'count': len(times), 'type': 'SCALAR',
             'min': [min(times)], 'max': [max(times)]},
            {'bufferView': 3, 'componentType': 5126, 'count': len(values), 'type': 'VEC4' if len(values[0]) == 4
             else 'VEC3'},
        ],
        'animations': [{'samplers': [{'input': 2, 'output': 3}],
                        'channels': [{'sampler': 0, 'target': {'node': animated_node, 'path': path_name}}]}],
    }
    write_gltf(path, doc, blobs)


def rect(x0, x1, y0, y1):
    return [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], [0, 1, 2, 0, 2, 3]


COMMON = ['-q', '--device', DEVICE, '--background', '0,0,0', '--default-light', 'off', '--max-depth', '0']


def render(candela, scene, out, size, spp, *options, written=None):
    r = run([candela, 'render', scene, '-o', out, '--width', str(size), '--height', str(size), '--spp', str(spp),
             *COMMON, *options])
    if r.returncode != 0:
        print(r.stderr)
        return None
    return oiio.ImageBuf(written or out).get_pixels(oiio.FLOAT)[:, :, 0]


def quad_columns(image):
    """Mean of each column over the rows the quad spans (|y| < 0.5: rows 16 to 47 of 64)."""
    return image[18:46, :].mean(axis=0)


def streak(size, half_width, shift):
    """Per-column coverage of a box of half-width `half_width` moving uniformly over
    [-shift/2, shift/2] (units; 2 units across `size` pixels), at the column centres."""
    x = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    plateau, end = half_width - shift / 2, half_width + shift / 2
    return np.clip((end - np.abs(x)) / (end - plateau), 0.0, 1.0)


def check_translation(candela, tmp):
    scene = os.path.join(tmp, 'slide.gltf')
    pos, idx = rect(-0.25, 0.25, -0.5, 0.5)
    write_scene(scene, pos, idx, [0.0, 2.0], 'translation', [(-1, 0, 0), (1, 0, 0)], 0)
    want = streak(64, 0.25, 0.25)
    sharp = render(candela, scene, os.path.join(tmp, 'sharp.exr'), 64, 16, '--anim-time', '1')
    check(sharp is not None, 'renders the quad at --anim-time 1 without --shutter')
    if sharp is None:
        return
    cols = quad_columns(sharp)
    check(np.all((cols == 0) | (cols == 1)) and abs(cols.sum() - 16) < 1e-6,
          f'without --shutter its edges are sharp: 16 full columns ({cols.sum():.3f})')
    out = os.path.join(tmp, 'blur.exr')
    # 0.25 s at 4 fps is one frame: -0.5:0.5 frames around t = 1 s
    blur = render(candela, scene, out, 64, 64, '--anim-time', '1', '--fps', '4', '--shutter', '-0.5:0.5')
    check(blur is not None, 'renders it with --shutter -0.5:0.5')
    if blur is None:
        return
    cols = quad_columns(blur)
    err = np.abs(cols - want).max()
    print('  columns 20..44 (measured / analytic):', ' '.join(f'{a:.2f}/{b:.2f}' for a, b in
                                                            zip(cols[20:44], want[20:44])))
    check(err < 0.05, f'the streak is the plateau with linear ramps 8 px long (largest column error {err:.3f})')
    meta = oiio.ImageInput.open(out).spec().get_string_attribute('candela:shutter')
    check(meta == '-0.5:0.5 in 4 steps', f'the metadata record the shutter: {meta}')
    frames = render(candela, scene, os.path.join(tmp, 'seq_#.exr'), 64, 64, '--frames', '4:4', '--fps', '4',
                    '--shutter', '-0.5:0.5', written=os.path.join(tmp, 'seq_4.exr'))
    check(frames is not None, 'renders frame 4 of --frames with --shutter')
    if frames is None:
        return
    err = np.abs(quad_columns(frames) - want).max()
    check(err < 0.05, f'frame 4 of --frames at 4 fps gives the same streak (largest column error {err:.3f})')
    # The camera moving the other way instead: the same streak
    moving = os.path.join(tmp, 'camera.gltf')
    write_scene(moving, pos, idx, [0.0, 2.0], 'translation', [(1, 0, 5), (-1, 0, 5)], 1)
    cam = render(candela, moving, os.path.join(tmp, 'camera.exr'), 64, 64, '--anim-time', '1', '--fps', '4',
                 '--shutter', '-0.5:0.5')
    if cam is not None:
        err = np.abs(quad_columns(cam) - want).max()
        check(err < 0.05, f'a camera moving instead gives the same streak (largest column error {err:.3f})')
    else:
        check(False, 'renders the moving camera with --shutter')


def check_rotation(candela, tmp):
    scene = os.path.join(tmp, 'bar.gltf')
    half, w = 0.8, 0.04
    pos, idx = rect(-half, half, -w / 2, w / 2)
    s = math.sin(math.pi / 4)
    write_scene(scene, pos, idx, [0.0, 1.0], 'rotation', [(0, 0, 0, 1), (0, 0, s, s)], 0)
    size = 128
    img = render(candela, scene, os.path.join(tmp, 'bar.exr'), size, 32, '--anim-time', '0', '--fps', '1',
                 '--shutter', '0:1')
    check(img is not None, 'renders the bar turning 90 degrees with --shutter 0:1')
    if img is None:
        return
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(c, -c)
    r, phi = np.hypot(x, y), np.mod(np.arctan2(y, x), np.pi)  # the bar covers phi and phi + pi
    inside = (phi > 0.15) & (phi < np.pi / 2 - 0.15)
    worst = 0.0
    for r0 in (0.2, 0.3, 0.4, 0.5, 0.6):
        ring = (r >= r0) & (r < r0 + 0.1)
        measured = img[ring & inside].mean()
        rm = r[ring & inside]
        analytic = (2 * np.arcsin(w / (2 * rm)) / (np.pi / 2)).mean()
        worst = max(worst, abs(measured / analytic - 1))
        print(f'  r {r0:.1f}-{r0 + 0.1:.1f}: coverage {measured:.4f}, analytic {analytic:.4f}')
    check(worst < 0.08, f'inside the swept quarter the coverage is the bar\'s angular fraction (worst {worst:.3f})')
    outside = (phi > np.pi / 2 + 0.15) & (phi < np.pi - 0.15) & (r > 0.3)
    check(img[outside].max() == 0, f'outside the swept quarter nothing is covered ({img[outside].max():.3f})')


def check_errors(candela, tmp):
    scene = os.path.join(tmp, 'slide.gltf')
    out = os.path.join(tmp, 'bad.exr')
    for opts, says in ((['--shutter', '0:0.5'], '--shutter needs --anim-time or --frames'),
                       (['--anim-time', '1', '--shutter', '0.5:0'], '--shutter must be OPEN:CLOSE'),
                       (['--anim-time', '1', '--shutter', 'x'], '--shutter must be OPEN:CLOSE'),
                       (['--anim-time', '1', '--shutter', '0:1', '--shutter-steps', '0'], '--shutter-steps')):
        r = run([candela, 'render', scene, '-o', out, *COMMON, *opts])
        lines = r.stderr.strip().splitlines()
        check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error:') and says in lines[0],
              f'{" ".join(opts)}: one error line ({r.stderr.strip()})')


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    candela = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory() as tmp:
        check_translation(candela, tmp)
        check_rotation(candela, tmp)
        check_errors(candela, tmp)
    finish()
    print('all passed')


if __name__ == '__main__':
    main()
