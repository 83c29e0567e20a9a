#!/usr/bin/python3
"""Animations through the command line: --anim-time and --animation on real renders.

- An emissive square seen by an orthographic camera (4 scene units across 64 pixels: 16
  pixels a unit), moved by a LINEAR translation from x = -1 at t = 0 to x = +1 at t = 2: its
  silhouette's centroid at --anim-time 0.5 and 1.5 lies 16 pixels apart (and at -8 and +8
  from the centre); after the last key (t = 5) it stays at the end value; without
  --anim-time it is at the rest pose (x = 0). The metadata record the pose.
- Bad input (unknown animation, negative or non-finite time, --animation alone) is one
  `candela: error:` line and exit 1.
- A sequence (--frames 0:48:24 at 24 fps) of the square: three files named by the '#' run,
  the square at -16, 0 and +16 pixels, the kernel compiled once (a fresh kernel cache: one
  build announced, the later frames' stats kernel_from_cache), a progress line per frame;
  --skip-existing renders only a missing frame and one an interruption left short; a
  sequence whose output has no '#' is one error before anything renders; frame f renders with
  seed --seed + f (two frames of one pose differ, a second run repeats the first).
- With the sample assets (../shared/gltf-samples): `candela info` lists Fox's three
  animations with their durations; SimpleSkin at +90 and -90 degrees of its joint (1 s, 4 s,
  and +-22.5 between keys) gives mirror-image silhouettes; SimpleSkin and AnimatedMorphSphere
  posed at a time differ from their rest pose seen by the same camera.
On CANDELA_TEST_DEVICE (default pocl); the sample assets' checks on PoCL only.
Usage: animation_test.py path/to/candela repo_root
"""
import json
import os
import struct
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio
from candela_test_util import check, exr_metadata as metadata, finish, run, write_gltf

DEVICE = os.environ.get('CANDELA_TEST_DEVICE', 'pocl')  # the sample assets' checks run on PoCL only


def sliding_square(path):
    """A unit-half-size emissive square in z = 0 at node 0, an animation 'slide' moving it
    along x, and an orthographic camera (xmag = ymag = 2) at z = 5 looking down -z."""
    pos = [(-0.5, -0.5, 0), (0.5, -0.5, 0), (0.5, 0.5, 0), (-0.5, 0.5, 0)]
    idx = [0, 1, 2, 0, 2, 3]
    times = [0.0, 2.0]
    moves = [(-1.0, 0, 0), (1.0, 0, 0)]
    blobs = [b"".join(struct.pack("<3f", *p) for p in pos), b"".join(struct.pack("<H", i) for i in idx),
             b"".join(struct.pack("<f", t) for t in times), b"".join(struct.pack("<3f", *m) for m in moves)]
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_specular"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 2, "znear": 0.1, "zfar": 10}}],
        # (no specular layer: the plain diffuse kernel, a short build on every device)
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0},
                       "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-0.5, -0.5, 0], "max": [0.5, 0.5, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [2]},
            {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
        ],
        "animations": [{"name": "slide", "samplers": [{"input": 2, "output": 3}],
                        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}]}],
    }
    write_gltf(path, doc, blobs)


def render(candela, scene, out, *options):
    r = run([candela, 'render', scene, '-o', out, '-q', '--device', DEVICE, '--spp', '4', *options])
    if r.returncode != 0:
        print(r.stderr)
    return r


def pixels(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3]


def centroid_x(image):
    lum = image.mean(axis=2)
    w = lum / lum.sum()
    return float((w.sum(axis=0) * (np.arange(lum.shape[1]) + 0.5)).sum())


def check_translation(candela, tmp):
    scene = os.path.join(tmp, 'slide.gltf')
    sliding_square(scene)
    common = ['--width', '64', '--height', '64', '--background', '0,0,0', '--default-light', 'off', '--max-depth', '1']
    x = {}
    for name, opts in (('rest', []), ('t0.5', ['--anim-time', '0.5']), ('t1.5', ['--anim-time', '1.5', '--animation',
                                                                                  'slide']),
                       ('t5', ['--anim-time', '5', '--animation', '0'])):
        out = os.path.join(tmp, name + '.exr')
        r = render(candela, scene, out, *common, *opts)
        check(r.returncode == 0, f'renders the sliding square {" ".join(opts) or "at rest"}')
        if r.returncode != 0:
            return
        x[name] = centroid_x(pixels(out)) - 32.0
        if name == 't1.5':
            meta = metadata(out)
            check(meta.get('anim_time') == '1.5' and meta.get('animation') == 'slide',
                  f'the metadata record the pose: anim_time {meta.get("anim_time")}, animation {meta.get("animation")}')
        if name == 'rest':
            meta = metadata(out)
            check(meta.get('anim_time') == 'none', f'the rest pose is recorded as anim_time none ({meta.get("anim_time")})')
    info = run([candela, 'info', scene, '--anim-time', '1.5']).stdout
    check('posed at 1.5 s by all its animations' in info and 'bounds (0, -0.5, 0) to (1, 0.5, 0)' in info,
          'candela info --anim-time 1.5 gives the posed bounds, x from 0 to 1')
    print('  centroid x offsets (pixels):', {k: round(v, 3) for k, v in x.items()})
    check(abs(x['rest']) < 0.2, f'at rest the square is centred ({x["rest"]:.3f} px)')
    check(abs(x['t0.5'] + 8) < 0.2, f'at t = 0.5 it is 0.5 units (8 px) left of centre ({x["t0.5"]:.3f} px)')
    check(abs(x['t1.5'] - 8) < 0.2, f'at t = 1.5 it is 8 px right of centre ({x["t1.5"]:.3f} px)')
    check(abs(x['t1.5'] - x['t0.5'] - 16) < 0.2, f'between them it moved 1 unit, 16 px ({x["t1.5"] - x["t0.5"]:.3f})')
    check(abs(x['t5'] - 16) < 0.2, f'after the last key it stays at x = +1, 16 px ({x["t5"]:.3f} px)')
    return scene


def check_errors(candela, scene, tmp):
    out = os.path.join(tmp, 'bad.png')
    for opts in (['--anim-time', '-1'], ['--anim-time', 'nan'], ['--anim-time', 'inf'],
                 ['--anim-time', '1', '--animation', 'walk'], ['--anim-time', '1', '--animation', '3'],
                 ['--animation', 'slide']):
        r = run([candela, 'render', scene, '-o', out, '-q', '--device', 'pocl', '--spp', '1', *opts])
        lines = r.stderr.strip().splitlines()
        check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error:'),
              f'{" ".join(opts)}: one error line, exit 1 ({r.returncode}: {r.stderr.strip()})')


def check_sequence(candela, scene, tmp):
    common = ['--width', '64', '--height', '64', '--background', '0,0,0', '--default-light', 'off', '--max-depth', '1',
              '--device', DEVICE, '--spp', '4']
    env = dict(os.environ, CANDELA_CACHE_DIR=os.path.join(tmp, 'fresh-cache'))
    seq = os.path.join(tmp, 'seq')
    os.mkdir(seq)
    args = [candela, 'render', scene, '-o', os.path.join(seq, 'f_###.exr'), '--stats', os.path.join(seq, 's_###.json'),
            '--frames', '0:48:24', '--fps', '24', *common]
    r = run(args, env=env)
    check(r.returncode == 0, f'a three-frame sequence renders ({r.stderr.strip()[-300:]})')
    names = sorted(os.listdir(seq))
    want = ['f_000.exr', 'f_024.exr', 'f_048.exr', 's_000.json', 's_024.json', 's_048.json']
    check(names == want, f'its files take the frame numbers: {names}')
    if r.returncode != 0 or names != want:
        return
    builds = r.stderr.count('compiling the render kernel')
    check(builds == 1, f'the kernel is compiled once for the sequence ({builds} builds announced)')
    cached = [json.load(open(os.path.join(seq, f's_{f:03d}.json')))['kernel_from_cache'] for f in (0, 24, 48)]
    check(cached == [False, True, True], f'the later frames take the kernel built for the first ({cached})')
    progress = [line for line in r.stderr.splitlines() if line.startswith('frame ')]
    check(len(progress) == 3 and progress[1] == 'frame 24 (2 of 3) at 1 s', f'a progress line per frame: {progress}')
    x = [centroid_x(pixels(os.path.join(seq, f'f_{f:03d}.exr'))) - 32.0 for f in (0, 24, 48)]
    check(all(abs(a - b) < 0.2 for a, b in zip(x, (-16, 0, 16))),
          f'frame f poses the square at f / 24 s: x = {[round(v, 3) for v in x]} px (want -16, 0, 16)')
    times = [metadata(os.path.join(seq, f'f_{f:03d}.exr')).get('anim_time') for f in (0, 24, 48)]
    check(times == ['0', '1', '2'], f'each frame records its moment: anim_time {times}')

    # Resuming: a missing frame and one an interruption left short are rendered, the others kept
    os.remove(os.path.join(seq, 'f_024.exr'))
    kept = os.path.getmtime(os.path.join(seq, 'f_000.exr'))
    r = run(args + ['--skip-existing'], env=env)
    check(r.returncode == 0 and '1 frame rendered (2 skipped' in r.stderr and
          os.path.exists(os.path.join(seq, 'f_024.exr')) and os.path.getmtime(os.path.join(seq, 'f_000.exr')) == kept,
          f'--skip-existing renders only the missing frame ({r.stderr.strip()[-200:]})')
    # 64 samples in launches of one sample: the interruption comes after the first pass
    short = [candela, 'render', scene, '-o', os.path.join(seq, 'f_###.exr'), '--frames', '48:72:24',
             *common[:-1], '64']
    env_stop = dict(env, CANDELA_RAISE_AT='later-pass:INT', CANDELA_LAUNCH_SECONDS='0.0001')
    r = run(short, env=env_stop)
    stopped = metadata(os.path.join(seq, 'f_048.exr')).get('spp')
    check(r.returncode == 130 and not os.path.exists(os.path.join(seq, 'f_072.exr')) and stopped not in (None, '64'),
          f'Ctrl-C writes the frame in progress ({stopped} spp) and stops the sequence (exit {r.returncode})')
    r = run(short + ['--skip-existing'], env=env)
    check(r.returncode == 0 and '2 frames rendered (0 skipped' in r.stderr and
          metadata(os.path.join(seq, 'f_048.exr')).get('spp') == '64',
          f'--skip-existing renders the interrupted frame again ({r.stderr.strip()[-200:]})')

    # Seeds: frame f renders with --seed + f; two frames of one pose differ in their noise, a
    # second run of the sequence repeats it bit for bit
    # (60 px: the square's edges cut pixels in half, where the samples' positions tell)
    still = [candela, 'render', scene, '-o', os.path.join(seq, 'still_###.exr'), '--frames', '120:121', '--seed', '5',
             '--width', '60', '--height', '60', *common[4:]]
    images = []
    for _ in range(2):
        r = run(still)
        images.append([pixels(os.path.join(seq, f'still_{f}.exr')) for f in (120, 121)] if r.returncode == 0 else None)
    seeds = [metadata(os.path.join(seq, f'still_{f}.exr')).get('seed') for f in (120, 121)] if images[0] else None
    check(seeds == ['125', '126'], f'frame f renders with seed --seed + f ({seeds})')
    check(images[0] is not None and not np.array_equal(*images[0]),
          'two frames of one pose differ in their noise (decorrelated)')
    check(images[1] is not None and all(np.array_equal(a, b) for a, b in zip(*images)),
          'and a second run of the sequence repeats it bit for bit')

    # '#' patterns: a run shorter than the number keeps it whole
    r = run([candela, 'render', scene, '-o', os.path.join(seq, 'one_#.exr'), '--frames', '9:10', *common])
    check(r.returncode == 0 and os.path.exists(os.path.join(seq, 'one_9.exr')) and
          os.path.exists(os.path.join(seq, 'one_10.exr')), 'a single # takes 9 and 10')
    for opts in (['-o', os.path.join(seq, 'plain.exr')],
                 ['-o', os.path.join(seq, 'p_#.exr'), '--stats', os.path.join(seq, 'plain.json')]):
        r = run([candela, 'render', scene, *opts, '--frames', '0:2', *common])
        lines = r.stderr.strip().splitlines()
        check(r.returncode == 1 and len(lines) == 1 and 'needs a run of #' in lines[0] and
              not os.path.exists(os.path.join(seq, 'p_0.exr')) and not os.path.exists(os.path.join(seq, 'plain.exr')),
              f'a sequence writing a file without #: one error before rendering ({r.stderr.strip()})')
    for opts in (['--frames', '3:1'], ['--frames', '0:4:0'], ['--frames', '1'], ['--frames', '0:2', '--anim-time', '1'],
                 ['--fps', '0', '--frames', '0:2'], ['--skip-existing']):
        r = run([candela, 'render', scene, '-o', os.path.join(seq, 'e_#.exr'), *opts, *common])
        lines = r.stderr.strip().splitlines()
        check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error:'),
              f'{" ".join(opts)}: one error line, exit 1 ({r.stderr.strip()})')


def check_samples(candela, tmp):
    sys.path.insert(0, os.path.join(sys.argv[2], 'scripts'))
    import candela_tools
    samples = candela_tools.samples_folder()
    if not os.path.isdir(samples):
        print('skip  the sample assets (not found)')
        return
    fox = os.path.join(samples, 'Fox', 'Fox.gltf')
    info = run([candela, 'info', fox]).stdout
    for line in ("animations: 3", "0: 'Survey', 0 to 3.417 s, 21 channels", "1: 'Walk', 0 to 0.7083 s",
                 "2: 'Run', 0 to 1.158 s", "rotation of 20 nodes, translation of 1 node"):
        check(line in info, f'candela info Fox.gltf lists {line!r}')
    check_skin_mirror(candela, tmp, samples)
    # A file without a camera: the sequence keeps the first frame's framing
    stats = os.path.join(tmp, 'fox_##.json')
    r = run([candela, 'render', fox, '-o', os.path.join(tmp, 'fox_##.png'), '--stats', stats, '--frames', '0:21:21',
             '--animation', 'Survey', '--device', 'pocl', '--spp', '2', '--width', '48', '-q'])
    cams = [json.load(open(stats.replace('##', f))).get('camera') for f in ('00', '21')] if r.returncode == 0 else []
    check(len(cams) == 2 and cams[0] == cams[1], 'a sequence of a file without a camera keeps its first framing')
    view = ['--width', '96', '--height', '96']
    for name, path, t, camera in (
            ('SimpleSkin', os.path.join(samples, 'SimpleSkin', 'SimpleSkin.gltf'), '1.5',
             ['--look-from', '0,1,4', '--look-at', '0,1,0']),
            ('AnimatedMorphSphere', os.path.join(samples, 'AnimatedMorphSphere', 'glTF', 'AnimatedMorphSphere.gltf'),
             '2', ['--look-from', '0,0,4', '--look-at', '0,0,0'])):
        if not os.path.exists(path):
            print(f'skip  {name} (not found)')
            continue
        rest, posed = os.path.join(tmp, name + '-rest.exr'), os.path.join(tmp, name + '-posed.exr')
        ok = render(candela, path, rest, *view, *camera).returncode == 0
        ok = ok and render(candela, path, posed, *view, *camera, '--anim-time', t).returncode == 0
        check(ok, f'{name} renders at rest and at --anim-time {t}')
        if not ok:
            continue
        a, b = pixels(rest), pixels(posed)
        changed = float((np.abs(a - b).max(axis=2) > 0.05 * max(a.max(), 1e-6)).mean())
        check(changed > 0.03, f'{name} posed at {t} s differs from its rest pose ({changed:.1%} of the pixels)')


def check_skin_mirror(candela, tmp, samples):
    """SimpleSkin's joint turns +90 degrees about z at t = 1 s and -90 at t = 4 s (LINEAR keys),
    +22.5 at 0.25 s and -22.5 at 3.25 s (halfway between keys); the mesh is symmetric about
    x = 0. Seen from +z through that axis, each pair's silhouettes are mirror images
    (intersection over union at least 0.98), and far from equal unmirrored."""
    path = os.path.join(samples, 'SimpleSkin', 'SimpleSkin.gltf')
    if not os.path.exists(path):
        print('skip  SimpleSkin (not found)')
        return
    sil = {}
    for t in ('1', '4', '0.25', '3.25'):
        out = os.path.join(tmp, f'skin-{t}.exr')
        # --max-depth 0: the white background where the camera ray misses, black on the mesh
        r = render(candela, path, out, '--anim-time', t, '--width', '96', '--height', '96', '--max-depth', '0',
                   '--background', '1,1,1', '--default-light', 'off', '--look-from', '0,1,4', '--look-at', '0,1,0')
        if r.returncode != 0:
            check(False, f'SimpleSkin renders at {t} s')
            return
        sil[t] = pixels(out).mean(axis=2) < 0.5

    def iou(a, b):
        return float((a & b).sum()) / max(float((a | b).sum()), 1.0)

    for a, b in (('1', '4'), ('0.25', '3.25')):
        mirrored, plain = iou(sil[a], sil[b][:, ::-1]), iou(sil[a], sil[b])
        check(mirrored >= 0.98 and plain < 0.9,
              f'SimpleSkin at {a} s is the mirror image of {b} s (IoU {mirrored:.3f}; unmirrored {plain:.3f})')


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    candela = os.path.abspath(sys.argv[1])
    with tempfile.TemporaryDirectory() as tmp:
        scene = check_translation(candela, tmp)
        if scene:
            check_errors(candela, scene, tmp)
            check_sequence(candela, scene, tmp)
        if DEVICE == 'pocl':
            check_samples(candela, tmp)
    finish()
    print('all passed')


if __name__ == '__main__':
    main()
