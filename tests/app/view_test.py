#!/usr/bin/python3
"""candela view driven as a person drives it, under Xvfb with Mesa's software OpenGL:
- no display, no OpenGL context (Mesa without its drivers), a missing scene: one error line
  (besides libGL's own), exit 1;
- the Cornell box in a 128x128 window at --spp 8: once the title says 8 spp (not the
  preview), a screenshot of the window (xwd, the panel hidden with Tab) equals `candela render` with the options the P
  key prints and --spp 8 (the same samples: each channel within 2 of 255, means within 0.5);
- a left drag (xdotool) changes the printed camera and the window, and the render of the new
  printed options equals the new screenshot;
- the S key writes OUT-0001.png (the screenshot's pixels) and OUT-0001.exr (the render's
  linear image at the same spp, means per channel within 0.5 %);
- L (--default-light auto, on, off) loads the scene again: the printed options, now with
  --default-light on, given to render equal the window (it prints the time the load took);
- a double-click on the back wall moves the printed --look-at onto the wall's plane (a face of
  the box's bounds), --look-from unchanged;
- V in a view with --aov albedo shows the albedo as `render -o FILE.png:albedo` writes it, then
  the standard error (grey, its largest white), then the image again; N (where Open Image
  Denoise loads) the image as `render --denoise` writes it;
- Escape closes the window: exit 0, with the line timing the frames that followed the drag;
  SIGINT to a second view: exit 0 within 5 s.
Skipped (77) without Xvfb, xdotool or xwd (scripts/setup.sh installs them), or a candela
built without GLFW.
Usage: view_test.py path/to/candela repo_root
"""
import json
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenImageIO as oiio

SKIP = 77
SIZE = 128
SPP = 8
failures = []


def check(ok, what):
    print(('ok    ' if ok else 'FAIL  ') + what, flush=True)
    if not ok:
        failures.append(what)


def start_xvfb():
    """Xvfb on a free display number (-displayfd); returns (process, ':N')"""
    read_end, write_end = os.pipe()
    xvfb = subprocess.Popen(['Xvfb', '-displayfd', str(write_end), '-screen', '0', '320x240x24', '-nolisten', 'tcp'],
                            pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_end)
    number = b''
    while not number.endswith(b'\n'):
        chunk = os.read(read_end, 16)
        if not chunk:
            raise RuntimeError('Xvfb did not start')
        number += chunk
    os.close(read_end)
    return xvfb, ':' + number.decode().strip()


def xwd_pixels(window, env):
    """The window's pixels (rows top first, RGB uint8) from an xwd dump (X Window Dump format)"""
    data = subprocess.run(['xwd', '-silent', '-id', window], env=env, capture_output=True, check=True).stdout
    fields = struct.unpack('>25I', data[:100])
    (header_size, _, _, _, width, height, _, byte_order, _, _, _, bits_per_pixel, bytes_per_line, _, red_mask,
     green_mask, blue_mask, _, _, colours) = fields[:20]
    if bits_per_pixel != 32:
        raise RuntimeError('xwd: %d bits per pixel' % bits_per_pixel)
    start = header_size + 12 * colours
    rows = np.frombuffer(data[start:start + bytes_per_line * height], dtype='<u4' if byte_order == 0 else '>u4')
    words = rows.reshape(height, bytes_per_line // 4)[:, :width]

    def channel(mask):
        shift = (mask & -mask).bit_length() - 1
        return ((words & mask) >> shift).astype(np.uint8)

    return np.stack([channel(red_mask), channel(green_mask), channel(blue_mask)], axis=-1)


def png_pixels(path):
    return oiio.ImageBuf(path).get_pixels(oiio.UINT8)[:, :, :3]


def exr_rgb(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def scene_bounds(scene):
    """The bounds of a glTF's POSITION accessors (min, max: the box's walls for the Cornell box)"""
    with open(scene) as f:
        gltf = json.load(f)
    used = [p['attributes']['POSITION'] for m in gltf['meshes'] for p in m['primitives']]
    lo = np.min([gltf['accessors'][a]['min'] for a in used], axis=0)
    hi = np.max([gltf['accessors'][a]['max'] for a in used], axis=0)
    return lo, hi


def same_image(a, b):
    diff = np.abs(a.astype(int) - b.astype(int))
    return a.shape == b.shape and diff.max() <= 2 and float(diff.mean()) <= 0.5


def main():
    candela, root = os.path.abspath(sys.argv[1]), sys.argv[2]
    scene = os.path.join(root, 'scenes', 'cornell-box', 'cornell-box.gltf')
    device = os.environ.get('CANDELA_TEST_DEVICE', 'pocl')
    missing = [tool for tool in ('Xvfb', 'xdotool', 'xwd') if not shutil.which(tool)]
    if missing:
        print('skipped: %s not installed (scripts/setup.sh installs them)' % ', '.join(missing))
        return SKIP
    no_display = {k: v for k, v in os.environ.items() if k not in ('DISPLAY', 'WAYLAND_DISPLAY')}
    r = subprocess.run([candela, 'view', scene], env=no_display, capture_output=True, text=True)
    if 'built without GLFW' in r.stderr:
        print('skipped: candela was built without GLFW (libglfw3-dev)')
        return SKIP
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error: no display'),
          'no display: one error line, exit 1 (%d: %s)' % (r.returncode, r.stderr.strip()))

    xvfb, display = start_xvfb()
    env = {**os.environ, 'DISPLAY': display}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            run_view(candela, scene, device, env, tmp)
    finally:
        xvfb.terminate()
        xvfb.wait()
    print('%d failures' % len(failures))
    return 1 if failures else 0


def xdotool(env, *args):
    return subprocess.run(['xdotool', *args], env=env, capture_output=True, text=True).stdout.strip()


def run_view(candela, scene, device, env, tmp):
    r = subprocess.run([candela, 'view', os.path.join(tmp, 'missing.gltf')], env=env, capture_output=True, text=True)
    lines = r.stderr.strip().splitlines()
    check(r.returncode == 1 and len(lines) == 1 and lines[0].startswith('candela: error:'),
          'a missing scene: one error line, exit 1 (%d: %s)' % (r.returncode, r.stderr.strip()))

    # Mesa without its drivers: no OpenGL context (libGL says why on stderr, candela in one line)
    r = subprocess.run([candela, 'view', scene], env={**env, 'LIBGL_DRIVERS_PATH': tmp}, capture_output=True,
                       text=True)
    ours = [line for line in r.stderr.splitlines() if line.startswith('candela')]
    check(r.returncode == 1 and len(ours) == 1 and 'OpenGL' in ours[0],
          'no OpenGL context: one error line, exit 1 (%d: %s)' % (r.returncode, ' / '.join(ours)))

    out_path, err_path = os.path.join(tmp, 'out.txt'), os.path.join(tmp, 'err.txt')
    common = ['--device', device, '--width', str(SIZE), '--height', str(SIZE), '--spp', str(SPP)]
    with open(out_path, 'w') as out, open(err_path, 'w') as err:
        view = subprocess.Popen([candela, 'view', scene, *common, '-o', os.path.join(tmp, 'shot.png')], env=env,
                                stdout=out, stderr=err)
    try:
        drive(candela, scene, device, env, tmp, view, out_path, common)
    finally:
        if view.poll() is None:
            view.kill()
            view.wait()
    with open(err_path) as f:
        err = f.read()
    timing = re.search(r'camera change to updated frame: median ([\d.]+) ms, max ([\d.]+) ms', err)
    check(timing is not None, 'the view timed the frames after the drag: %s' % (timing.group(0) if timing else err))

    # Ctrl-C: exits at once, status 0
    # (with --aov albedo: V shows the albedo AOV as `render -o FILE.png:albedo` writes it)
    second = subprocess.Popen([candela, 'view', scene, *common, '--aov', 'albedo'], env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    window = wait_for_title(env, second, r': %d spp, ' % SPP)
    check(window is not None, 'a second view renders')
    if window is not None:
        xdotool(env, 'key', '--window', window, 'Tab')
        time.sleep(0.3)
        beauty = xwd_pixels(window, env)
        xdotool(env, 'key', '--window', window, 'v')
        albedo, end = beauty, time.time() + 10
        while time.time() < end and np.array_equal(albedo, beauty):
            time.sleep(0.2)
            albedo = xwd_pixels(window, env)
        check(not same_image(albedo, beauty), 'V changed the window')
        out = os.path.join(tmp, 'albedo.png')
        r = subprocess.run([candela, 'render', scene, *common, '-q', '--camera', '0', '--aov', 'albedo', '-o',
                            out + ':albedo'], capture_output=True, text=True)
        check(r.returncode == 0 and same_image(albedo, png_pixels(out)),
              'V shows the albedo AOV as render writes it (%s)' % r.stderr.strip())
        xdotool(env, 'key', '--window', window, 'v')  # the standard error: grey
        error, end = albedo, time.time() + 10
        while time.time() < end and np.array_equal(error, albedo):
            time.sleep(0.2)
            error = xwd_pixels(window, env)
        error = error.astype(int)
        check(np.all(error[:, :, 0] == error[:, :, 1]) and np.all(error[:, :, 1] == error[:, :, 2]) and
              error.max() == 255 and error.std() > 5, 'V again shows the standard error in grey')
        xdotool(env, 'key', '--window', window, 'v')
        again, end = error, time.time() + 10
        while time.time() < end and np.array_equal(again, error):
            time.sleep(0.2)
            again = xwd_pixels(window, env)
        check(np.array_equal(again, beauty), 'V once more shows the image again')
        # N: denoised as render --denoise writes it, where Open Image Denoise loads
        out = os.path.join(tmp, 'denoised.png')
        r = subprocess.run([candela, 'render', scene, *common, '-q', '--camera', '0', '--aov', 'albedo', '--denoise',
                            '-o', out], capture_output=True, text=True)
        if r.returncode == 0 and 'error' not in r.stderr:
            xdotool(env, 'key', '--window', window, 'n')
            denoised, end = again, time.time() + 20
            while time.time() < end and np.array_equal(denoised, again):
                time.sleep(0.2)
                denoised = xwd_pixels(window, env)
            check(same_image(denoised, png_pixels(out)), 'N shows the image as render --denoise writes it')
        else:
            print('note: no Open Image Denoise: %s' % r.stderr.strip())
    second.send_signal(signal.SIGINT)
    try:
        status = second.wait(timeout=5)
    except subprocess.TimeoutExpired:
        second.kill()
        status = 'still running after 5 s'
    check(status == 0, 'SIGINT: exit 0 at once (%s)' % status)


def wait_for_title(env, process, pattern, window=None, seconds=600):
    """The window (its id) once its title matches `pattern`; None when the view exits or time runs out"""
    end = time.time() + seconds
    while time.time() < end and process.poll() is None:
        if window is None:
            found = xdotool(env, 'search', '--name', '^candela view').split()
            window = found[0] if found else None
        if window and re.search(pattern, xdotool(env, 'getwindowname', window)):
            return window
        time.sleep(0.2)
    return None


def printed_camera(env, window, out_path, count):
    """Presses P; the options of the count-th `camera:` line it printed"""
    xdotool(env, 'key', '--window', window, 'p')
    end = time.time() + 10
    while time.time() < end:
        with open(out_path) as f:
            cameras = [line[len('camera: '):].split() for line in f if line.startswith('camera: ')]
        if len(cameras) >= count:
            return cameras[count - 1]
        time.sleep(0.1)
    return None


def reference(candela, scene, device, camera, out):
    cmd = [candela, 'render', scene, '--device', device, '--spp', str(SPP), '-q', *camera, '-o', out + '.png', '-o',
           out + '.exr']
    r = subprocess.run(cmd, capture_output=True, text=True)
    check(r.returncode == 0, 'render %s: %s' % (' '.join(camera), r.stderr.strip()))
    return png_pixels(out + '.png')


def drive(candela, scene, device, env, tmp, view, out_path, common):
    done = r': %d spp, ' % SPP  # the title at --spp samples, not the preview
    window = wait_for_title(env, view, done)
    check(window is not None, 'the window shows %d spp' % SPP)
    if window is None:
        return
    geometry = xdotool(env, 'getwindowgeometry', window)
    check('Geometry: %dx%d' % (SIZE, SIZE) in geometry, 'the window is %dx%d: %s' % (SIZE, SIZE, geometry))
    panel = xwd_pixels(window, env)
    xdotool(env, 'key', '--window', window, 'Tab')  # hides the panel
    time.sleep(0.5)
    shot = xwd_pixels(window, env)
    print('note: the panel %s' % ('shows until Tab' if not same_image(panel, shot) else 'is not built in'))
    check(float(shot.std()) > 5.0, 'the screenshot shows an image (std %.1f)' % shot.std())
    camera = printed_camera(env, window, out_path, 1)
    check(camera is not None and camera[:2] == ['--camera', '0'], 'P prints the scene camera: %s' % camera)
    ref = reference(candela, scene, device, camera or [], os.path.join(tmp, 'first'))
    check(same_image(shot, ref), 'the window equals render of the printed camera (max diff %d, mean %.2f)' %
          (np.abs(shot.astype(int) - ref).max(), np.abs(shot.astype(int) - ref).mean()))

    # A left drag: the camera orbits
    xdotool(env, 'mousemove', '--window', window, '64', '64', 'mousedown', '1')
    for x in range(70, 101, 6):
        xdotool(env, 'mousemove', '--window', window, str(x), str(64 - (x - 64) // 3))
        time.sleep(0.05)
    xdotool(env, 'mouseup', '1')
    time.sleep(0.3)
    moved = printed_camera(env, window, out_path, 2)
    check(moved is not None and '--look-from' in moved and moved != camera, 'the drag changed the camera: %s' % moved)
    title = wait_for_title(env, view, done + '.*--look-from', window)
    check(title is not None, 'the window renders the new camera to %d spp' % SPP)
    after = xwd_pixels(window, env)
    check(not same_image(after, shot), 'the window changed')
    ref = reference(candela, scene, device, moved or [], os.path.join(tmp, 'moved'))
    check(same_image(after, ref), 'the window equals render of the printed camera after the drag (max diff %d)' %
          np.abs(after.astype(int) - ref).max())

    # S: the image as PNG (the window's pixels) and EXR (the linear estimate)
    xdotool(env, 'key', '--window', window, 's')
    png, exr = os.path.join(tmp, 'shot-0001.png'), os.path.join(tmp, 'shot-0001.exr')
    end = time.time() + 20
    while time.time() < end and not ('wrote %s' % exr) in open(out_path).read():
        time.sleep(0.1)
    written = open(out_path).read()
    check(('wrote %s' % png) in written and ('wrote %s' % exr) in written, 'S names the files it wrote')
    if os.path.exists(png) and os.path.exists(exr):
        check(same_image(png_pixels(png), after), 'the saved PNG shows the window')
        saved, rendered = exr_rgb(exr).mean(axis=(0, 1)), exr_rgb(os.path.join(tmp, 'moved.exr')).mean(axis=(0, 1))
        check(np.all(np.abs(saved - rendered) <= 0.005 * rendered + 1e-6),
              'the saved EXR matches render at %d spp: means %s vs %s' % (SPP, saved, rendered))

    # L: --default-light on (the scene loads again, the camera kept); the printed options
    # reproduce the window
    # (the box is closed: the studio adds nothing)
    xdotool(env, 'key', '--window', window, 'l')
    end = time.time() + 60
    while time.time() < end and 'loaded the scene again' not in open(out_path).read():
        time.sleep(0.1)
    loaded = re.search(r'loaded the scene again in ([\d.]+) s', open(out_path).read())
    check(loaded is not None, 'L loaded the scene again: %s' % (loaded.group(0) if loaded else None))
    lit = wait_for_title(env, view, done + '.*--look-from', window)
    relit = printed_camera(env, window, out_path, 3)
    check(lit is not None and relit is not None and relit[-2:] == ['--default-light', 'on'] and
          relit[:-2] == moved, 'L: the scene loads again with --default-light on: %s' % relit)
    on = xwd_pixels(window, env)
    ref = reference(candela, scene, device, relit or [], os.path.join(tmp, 'lit'))
    check(same_image(on, ref),
          'the window equals render with --default-light on (max diff %d)' % np.abs(on.astype(int) - ref).max())

    # A double-click: the pivot (--look-at) moves to the surface point under the cursor, the
    # camera stays where it is (--look-from)
    xdotool(env, 'mousemove', '--window', window, '40', '40', 'click', '--repeat', '2', '--delay', '80', '1')
    time.sleep(0.3)
    focused = printed_camera(env, window, out_path, 4)
    check(focused is not None and moved is not None and focused[focused.index('--look-from') + 1] ==
          moved[moved.index('--look-from') + 1] and focused[focused.index('--look-at') + 1] !=
          moved[moved.index('--look-at') + 1], 'the double-click moved the pivot, not the camera: %s' % focused)
    if focused is not None:
        at = np.array([float(x) for x in focused[focused.index('--look-at') + 1].split(',')])
        lo, hi = scene_bounds(scene)
        gap = np.minimum(np.abs(at - lo), np.abs(at - hi))
        check(np.all(at >= lo - 1e-4) and np.all(at <= hi + 1e-4) and gap.min() < 1e-4 * np.abs(hi - lo).max(),
              'the new pivot %s lies on a wall of the box (bounds %s..%s)' % (at, lo, hi))

    xdotool(env, 'key', '--window', window, 'Escape')
    try:
        status = view.wait(timeout=10)
    except subprocess.TimeoutExpired:
        status = 'still running after 10 s'
    check(status == 0, 'Escape closes the window: exit 0 (%s)' % status)


if __name__ == '__main__':
    sys.exit(main())
