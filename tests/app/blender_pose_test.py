#!/usr/bin/python3
"""Animation poses against Blender 3.4's glTF importer (scripts/compare/blender_pose.py).

Fox at three moments of Survey and two of Walk and Run (between keys, not only at them), and
SimpleSkin at its screenshot's moment (1 s: the joint at +90 degrees) and between keys (0.25 s), and
the morph targets of AnimatedMorphSphere and MorphStressTest at two moments each, posed by candela
and by Blender: their silhouettes seen by the same camera at 256 x 256 pixels overlap with an
intersection over union of at least 0.98. The metric tells poses apart: candela's silhouette at
one moment against Blender's at another of the same animation scores below 0.95.
Skipped (exit 77) without Debian's `blender` or the sample assets.
Usage: blender_pose_test.py path/to/candela repo_root [--device SEL (default: $CANDELA_TEST_DEVICE, else pocl)]
"""
import os
import shutil
import sys
import tempfile

from candela_test_util import SKIP, check, finish

SIZE = 256
FOX_VIEW = ['--look-from', '260,40,-10', '--look-at', '0,40,-10', '--fov', '45']  # the Fox from its right side
CASES = [  # (asset, animation, moments in seconds, camera)
    (('Fox', 'Fox.gltf'), 'Survey', (0.9, 2.3, 3.1), FOX_VIEW),
    (('Fox', 'Fox.gltf'), 'Walk', (0.2, 0.55), FOX_VIEW),
    (('Fox', 'Fox.gltf'), 'Run', (0.3, 0.85), FOX_VIEW),
    (('SimpleSkin', 'SimpleSkin.gltf'), '0', (1.0, 0.25), ['--look-from', '0.5,1,4', '--look-at', '0.5,1,0',
                                                           '--fov', '45']),
    # Morph targets (weights animated), framed as candela frames a file without a camera
    (('AnimatedMorphSphere', 'glTF', 'AnimatedMorphSphere.gltf'), 'Globe', (1.5, 4.0), []),
    (('MorphStressTest_bevy', 'MorphStressTest.gltf'), 'TheWave', (0.4, 1.1), []),
]

def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    candela, root = os.path.abspath(sys.argv[1]), sys.argv[2]
    device = (sys.argv[sys.argv.index('--device') + 1] if '--device' in sys.argv
              else os.environ.get('CANDELA_TEST_DEVICE', 'pocl'))
    sys.path.insert(0, os.path.join(root, 'scripts', 'compare'))
    import blender_pose as bp
    import candela_tools as ct
    blender = shutil.which('blender')
    if not blender:
        print('skip: blender is not installed (Debian package blender: CANDELA_EXTRA_PACKAGES=blender scripts/test installs it)')
        sys.exit(SKIP)
    samples = ct.samples_folder()
    if not os.path.isdir(samples):
        print('skip: the sample assets are not there (%s)' % samples)
        sys.exit(SKIP)
    for asset, animation, times, camera in CASES:
        path = os.path.join(samples, *asset)
        if not os.path.exists(path):
            print('skip  %s (not found)' % path)
            continue
        with tempfile.TemporaryDirectory() as tmp:
            try:
                geometry, info = bp.blender_poses(blender, path, animation, times, tmp)
                masks = [bp.candela_mask(candela, path, animation, t, SIZE, 16, camera, device, tmp) for t in times]
            except ct.UserError as e:
                check(False, '%s %s: %s' % (asset[-1], animation, e))
                continue
            theirs = [bp.project_mask(pos, tri, cam, SIZE) for (pos, tri), (_, cam) in zip(geometry, masks)]
            for t, (mine, _), other in zip(times, masks, theirs):
                value, na, nb = bp.iou(mine, other)
                check(value >= 0.98, '%s %s at %g s (Blender %s, frame %g at %g fps): IoU %.4f >= 0.98 '
                      '(candela %d px, Blender %d px)' % (asset[-1], animation, t, info['blender'], t * info['fps'],
                                                           info['fps'], value, na, nb))
            wrong, _, _ = bp.iou(masks[0][0], theirs[1])
            check(wrong < 0.95, '%s %s: candela at %g s against Blender at %g s differ (IoU %.4f < 0.95)' % (
                asset[-1], animation, times[0], times[1], wrong))
    finish()
    print('all passed')


if __name__ == '__main__':
    main()
