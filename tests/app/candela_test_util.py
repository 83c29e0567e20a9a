"""What the app tests share: a list of checks that fails the test at its end, running candela,
reading an EXR's channels and candela's metadata, and writing a small glTF file whose buffers
are embedded."""
import base64
import json
import re
import subprocess
import sys

SKIP = 77  # ctest's SKIP_RETURN_CODE for these tests
failures = []


def check(ok, what):
    print(('ok    ' if ok else 'FAIL  ') + what)
    if not ok:
        failures.append(what)
    return ok


def finish():
    """Exits 1 naming the count when a check failed."""
    if failures:
        print(f'{len(failures)} failed')
        sys.exit(1)


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, **kw)


def read_channels(path):
    """An image's channels by name (EXR, PNG, ...), as float32 arrays of shape (height, width)."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise OSError(f'cannot read {path}: {oiio.geterror()}')
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    inp.close()
    return {name: pixels[:, :, i] for i, name in enumerate(spec.channelnames)}


def exr_metadata(path, text=False):
    """candela's metadata (the `candela:` attributes) by name; as strings with text=True.
    Without OpenImageIO's Python module it reads `oiiotool --info -v` (strings); None when
    the file cannot be read."""
    try:
        import OpenImageIO as oiio
    except ImportError:
        out = run(['oiiotool', '--info', '-v', path])
        if out.returncode != 0:
            return None
        return dict(re.findall(r'^\s+candela:(\w+): "?(.*?)"?$', out.stdout, re.M))
    inp = oiio.ImageInput.open(path)
    if inp is None:
        return None
    meta = {a.name[len('candela:'):]: (str(a.value) if text else a.value)
            for a in inp.spec().extra_attribs if a.name.startswith('candela:')}
    inp.close()
    return meta


def write_gltf(path, doc, blobs):
    """Writes DOC to PATH with one embedded buffer holding BLOBS (bytes), each its own
    buffer view in order (4-byte aligned); DOC's accessors refer to them by index."""
    views, data = [], b''
    for blob in blobs:
        data += b'\0' * (-len(data) % 4)
        views.append({'buffer': 0, 'byteOffset': len(data), 'byteLength': len(blob)})
        data += blob
    doc = dict(doc, bufferViews=views, buffers=[{
        'byteLength': len(data), 'uri': 'data:application/octet-stream;base64,' + base64.b64encode(data).decode()}])
    with open(path, 'w') as f:
        json.dump(doc, f)
