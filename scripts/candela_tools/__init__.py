"""What the scripts under scripts/ share: running `candela render` and reading its statistics, reading
images (OpenImageIO and numpy), the error metrics, the sample assets' folder, the checkout's commit and
the results file of the documented figures. Blender Cycles lives in candela_tools.cycles, Mitsuba 3 in
candela_tools.mitsuba.

A script in a folder below scripts/ imports it with

    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    import candela_tools as ct

Numpy and OpenImageIO (Debian's python3-numpy and python3-openimageio: the scripts run with
/usr/bin/python3) are imported on first use: a script that only runs candela needs neither.
"""

import datetime
import hashlib
import json
import math
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BINARY = os.path.join(ROOT, "build", "candela")
EPSILON = 0.01  # relMSE's epsilon: mean (x - r)^2 / (r^2 + EPSILON)
RESULTS = os.path.join(ROOT, "docs", "figures", "results.json")
RESULTS_TABLE = os.path.join(ROOT, "docs", "results.py")
ERROR_PREFIX = "candela: error: "


class UserError(Exception):
    """A failure to report as one `candela: error:` line (fail())."""


class RenderError(UserError):
    """A `candela render` that failed: the message, its exit status (124: past the timeout) and stderr."""

    def __init__(self, message, returncode, stderr):
        super().__init__(message)
        self.returncode, self.stderr = returncode, stderr


def fail(message):
    print(ERROR_PREFIX + message, file=sys.stderr)
    sys.exit(1)


# ---- candela ----

class Render:
    """One finished `candela render`: its --stats (a dict, {} without stats), stderr and wall seconds."""

    def __init__(self, stats, stderr, wall):
        self.stats, self.stderr, self.wall = stats, stderr, wall

    def notes(self):
        """Its warning and note lines."""
        return [l for l in self.stderr.splitlines() if l.startswith(("warning", "note"))]


def render(scene, outputs, options=(), binary=None, stats=None, env=None, timeout=None):
    """Run `candela render SCENE -o OUTPUT... [--stats STATS] OPTIONS`. outputs: a path or a list of paths
    (none: []). Returns a Render; raises RenderError with candela's error line (or the exit status and the
    tail of stderr) when it fails or runs past timeout seconds."""
    if isinstance(outputs, str):
        outputs = [outputs]
    cmd = [binary or BINARY, "render", scene]
    for o in outputs:
        cmd += ["-o", o]
    if stats:
        cmd += ["--stats", stats]
    cmd += [str(o) for o in options]
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        raise RenderError("timed out after %d s" % timeout, 124, "timed out after %d s" % timeout)
    wall = time.monotonic() - start
    if p.returncode != 0:
        raise RenderError(error_of(p.returncode, p.stderr), p.returncode, p.stderr)
    data = {}
    if stats:
        with open(stats) as f:
            data = json.load(f)
    return Render(data, p.stderr, wall)


def error_of(returncode, stderr):
    """The message of a failed candela run: its `candela: error:` line, else the exit status and the tail of
    stderr."""
    lines = [l for l in stderr.splitlines() if l.startswith(ERROR_PREFIX)]
    if lines:
        return lines[0][len(ERROR_PREFIX):]
    return "candela render failed (exit %d): %s" % (returncode, stderr.strip()[-500:])


# ---- images ----

def numpy_oiio():
    """(numpy, OpenImageIO), or UserError naming the Debian packages."""
    try:
        import numpy
        import OpenImageIO
    except ImportError as e:
        raise UserError("this script needs numpy and OpenImageIO's Python module (Debian: python3-numpy "
                        "python3-openimageio; run it with /usr/bin/python3): %s" % e)
    return numpy, OpenImageIO


def read_image(path, what="image"):
    """(pixels, spec): every channel as float64, height x width x channels, and OpenImageIO's ImageSpec."""
    np, oiio = numpy_oiio()
    if not os.path.isfile(path):
        raise UserError("%s not found: %s" % (what, path))
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise UserError("cannot read %s %s: %s" % (what, path, oiio.geterror()))
    spec = inp.spec()
    pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    inp.close()
    if pixels is None:
        raise UserError("cannot read %s %s" % (what, path))
    return np.asarray(pixels, dtype=np.float64).reshape(spec.height, spec.width, spec.nchannels), spec


def read_rgb(path, what="image"):
    """(rgb, meta): the first three channels (one channel repeated), float64 H x W x 3, and the image's
    candela:* metadata without the prefix."""
    np, _ = numpy_oiio()
    pixels, spec = read_image(path, what)
    rgb = pixels[:, :, :3] if spec.nchannels >= 3 else np.repeat(pixels[:, :, :1], 3, axis=2)
    meta = {}
    for attr in spec.extra_attribs:
        if attr.name.startswith("candela:"):
            meta[attr.name[len("candela:"):]] = str(attr.value)
    return rgb, meta


def read_channels(path, channels, what="image"):
    """The named channels (e.g. "RGB", "RGBA", ["R", "G"]) as float64 H x W x len(channels)."""
    np, _ = numpy_oiio()
    pixels, spec = read_image(path, what)
    names = list(spec.channelnames)
    missing = [c for c in channels if c not in names]
    if missing:
        raise UserError("%s %s has no channel %s" % (what, path, ", ".join(missing)))
    return np.stack([pixels[:, :, names.index(c)] for c in channels], axis=-1)


def image_digest(path):
    """The first 16 hex digits of the SHA-256 of the image's pixels as 32-bit floats: equal exactly when two
    images are bit-identical."""
    _, oiio = numpy_oiio()
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise UserError("cannot read %s: %s" % (path, oiio.geterror()))
    data = inp.read_image(format=oiio.FLOAT)
    inp.close()
    return hashlib.sha256(data.tobytes()).hexdigest()[:16]


def write_image(path, pixels, fmt="float"):
    """Write an H x W x C array (float, or uint8 with fmt="uint8")."""
    np, oiio = numpy_oiio()
    h, w, c = pixels.shape
    out = oiio.ImageOutput.create(path)
    if out is None:
        raise UserError("cannot write %s: %s" % (path, oiio.geterror()))
    out.open(path, oiio.ImageSpec(w, h, c, fmt))
    out.write_image(np.ascontiguousarray(pixels.astype(np.float32) if fmt == "float" else pixels))
    out.close()


# ---- error metrics ----

def errors(image, reference, epsilon=EPSILON):
    """rel_mse = mean (x - r)^2 / (r^2 + epsilon), mse = mean (x - r)^2 and mae = mean |x - r| over all pixels
    and channels (x the image, r the reference)."""
    np, _ = numpy_oiio()
    if image.shape != reference.shape:
        raise UserError("the render is %dx%d but the reference is %dx%d" %
                        (image.shape[1], image.shape[0], reference.shape[1], reference.shape[0]))
    d = image - reference
    return {"rel_mse": float(np.mean(d * d / (reference * reference + epsilon))),
            "mse": float(np.mean(d * d)),
            "mae": float(np.mean(np.abs(d)))}


def rel_mse(image, reference, epsilon=EPSILON):
    return errors(image, reference, epsilon)["rel_mse"]


def fit_slope(xs, ys):
    """Least-squares slope of log(y) against log(x)."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((x - mx) ** 2 for x in lx)
    if sxx == 0:
        return float("nan")
    return sum((x - mx) * (y - my) for x, y in zip(lx, ly)) / sxx


def parse_ladder(text, option="--spp-ladder"):
    """Comma-separated sample counts, sorted, each once."""
    try:
        ladder = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UserError("%s expects comma-separated sample counts, e.g. 1,2,4,8; got '%s'" % (option, text))
    if not ladder or any(n < 1 for n in ladder):
        raise UserError("%s needs sample counts of at least 1; got '%s'" % (option, text))
    return sorted(set(ladder))


# ---- the checkout and the machine ----

def samples_folder():
    """../shared/gltf-samples beside the checkout (CANDELA_SAMPLES overrides; from a git worktree: beside the
    main checkout). The path is returned whether the folder exists or not."""
    if os.environ.get("CANDELA_SAMPLES"):
        return os.environ["CANDELA_SAMPLES"]
    here = os.path.join(os.path.dirname(ROOT), "shared", "gltf-samples")
    if os.path.isdir(here):
        return here
    try:
        common = subprocess.run(["git", "-C", ROOT, "rev-parse", "--path-format=absolute", "--git-common-dir"],
                                capture_output=True, text=True).stdout.strip()
    except OSError:
        common = ""
    if common:
        return os.path.join(os.path.dirname(os.path.dirname(common)), "shared", "gltf-samples")
    return here


def git_commit(dirty=False):
    """The checkout's short commit ("unknown" outside git); with dirty, "+dirty" when tracked files changed."""
    p = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    commit = p.stdout.strip() or "unknown"
    if dirty and subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                                capture_output=True, text=True).stdout.strip():
        commit += "+dirty"
    return commit


def load_average():
    """The 1-minute load average (nan where /proc/loadavg is missing)."""
    try:
        with open("/proc/loadavg") as f:
            return float(f.read().split()[0])
    except (OSError, ValueError, IndexError):
        return float("nan")


def cpu_description():
    """e.g. "2 cores, Intel(R) Xeon(R) CPU @ 2.20GHz": the host part of a recorded figure."""
    model = ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    cores = os.cpu_count() or 1
    return "%d core%s%s" % (cores, "" if cores == 1 else "s", ", " + model if model else "")


# ---- the documented figures ----

def record_result(key, figure, command, host, results=None):
    """Set the figure of target KEY in docs/figures/results.json ({"targets": [{"key", "target", "figure",
    "command", "host", "date", "commit"}]}): date today, commit the checkout's; an existing entry keeps its
    "target" (a new one gets an empty one, to be written by hand). Then regenerates the documents' table with
    docs/results.py when that exists."""
    path = results or RESULTS
    data = {"targets": []}
    if os.path.isfile(path):
        with open(path) as f:
            data = json.load(f)
    targets = data.setdefault("targets", [])
    old = next((t for t in targets if t.get("key") == key), None)
    entry = {"key": key, "target": old.get("target", "") if old else "", "figure": figure, "command": command,
             "host": host, "date": datetime.date.today().isoformat(), "commit": git_commit()}
    if old:
        targets[targets.index(old)] = entry
    else:
        targets.append(entry)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(data, f, indent=2, ensure_ascii=False)
        f.write("\n")
    print("recorded %s: %s" % (key, figure), file=sys.stderr)
    if results is None and os.path.isfile(RESULTS_TABLE):
        subprocess.run([sys.executable, RESULTS_TABLE], cwd=ROOT, check=True)
    return entry


SHORT_NAMES = {"cornell-box": "cornell", "suzanne-1m": "suzanne", "mesh-1m": "mesh1m", "mesh-10m": "mesh10m",
               "DamagedHelmet": "helmet", "2CylinderEngine": "engine", "Fox": "fox"}


def result_key(scene, what):
    """The results.json key of a figure WHAT (e.g. "vs-cycles") on SCENE: "cornell-vs-cycles"."""
    stem = os.path.splitext(os.path.basename(scene))[0]
    return "%s-%s" % (SHORT_NAMES.get(stem, stem), what)


_SCRIPT = os.path.abspath(sys.argv[0]) if sys.argv and sys.argv[0] else ""  # before a script changes folder


def command_line(argv=None):
    """This script's command line as the user would type it from the checkout's root."""
    import shlex
    if argv is None:
        argv, script = sys.argv, _SCRIPT
    else:
        script = os.path.abspath(argv[0])
    return " ".join(shlex.quote(a) for a in [os.path.relpath(script, ROOT)] + list(argv[1:]))
