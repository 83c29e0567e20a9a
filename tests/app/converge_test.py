"""scripts/compare/converge.py: the ladder's relMSE falls as 1/spp, the CSV has the documented columns,
the chart is written, and bad input gives one candela: error line.

Usage: /usr/bin/python3 tests/app/converge_test.py path/to/candela repo_root
The reference is exact: inside the closed furnace sphere (albedo 0.5, emission 0.5)
every pixel's radiance is 1, so the error has no reference noise in it.
"""
import csv
import math
import os
import subprocess
import sys
import tempfile
import unittest

CANDELA = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else "build/candela"
ROOT = os.path.abspath(sys.argv[2]) if len(sys.argv) > 2 else "."
SCRIPT = os.path.join(ROOT, "scripts", "compare", "converge.py")
SCENE = os.path.join(ROOT, "scenes", "furnace", "closed-sphere.gltf")

try:
    import numpy as np
    import OpenImageIO as oiio
    HAVE_DEPS = True
except ImportError:
    HAVE_DEPS = False
try:
    import matplotlib  # noqa: F401
    HAVE_MPL = True
except ImportError:
    HAVE_MPL = False


def write_exr(path, rgb):
    out = oiio.ImageOutput.create(path)
    out.open(path, oiio.ImageSpec(rgb.shape[1], rgb.shape[0], 3, oiio.FLOAT))
    out.write_image(rgb.astype(np.float32))
    out.close()


def run(*args, render_options=()):
    tail = ["--", *render_options] if render_options else []
    return subprocess.run([sys.executable, SCRIPT, *args, "--candela", CANDELA, "--device", "pocl", *tail],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@unittest.skipUnless(HAVE_DEPS, "numpy or OpenImageIO's Python module is missing (python3-numpy, python3-openimageio)")
class Converge(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.ref = os.path.join(cls.tmp.name, "one.exr")
        write_exr(cls.ref, np.ones((24, 24, 3)))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_ladder_falls_as_one_over_spp(self):
        ladder = [1, 2, 4, 8, 16, 32, 64]
        out_csv = os.path.join(self.tmp.name, "c.csv")
        chart = os.path.join(self.tmp.name, "c.png")
        args = [SCENE, "--reference", self.ref, "--spp-ladder", ",".join(map(str, ladder)), "--csv", out_csv,
                "--seed", "5", "--no-blender", "-q"]
        if HAVE_MPL:
            args += ["--chart", chart]
        # The independent sampler: its relMSE falls exactly as 1/spp (Sobol's may fall faster)
        p = run(*args, render_options=["--sampler", "independent"])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out_csv) as f:
            reader = csv.DictReader(f)
            self.assertEqual(reader.fieldnames, ["renderer", "device", "strategy", "spp", "seconds", "startup_seconds",
                                                 "rel_mse", "mse", "mae", "efficiency", "samples_per_second"])
            rows = list(reader)
        self.assertEqual([int(r["spp"]) for r in rows], ladder)
        for r in rows:
            self.assertEqual(r["renderer"], "candela")
            self.assertEqual(r["strategy"], "auto")
            self.assertIn("Portable Computing Language", r["device"])
            rel, mse, mae, sec = float(r["rel_mse"]), float(r["mse"]), float(r["mae"]), float(r["seconds"])
            self.assertGreater(sec, 0)
            self.assertGreaterEqual(float(r["startup_seconds"]), 0)
            self.assertGreater(rel, 0)
            # The reference is 1 everywhere: relMSE = MSE / (1 + epsilon)
            self.assertAlmostEqual(rel, mse / 1.01, delta=1e-6 * mse)
            self.assertLessEqual(mae, math.sqrt(mse) * (1 + 1e-9))
            self.assertAlmostEqual(float(r["efficiency"]), 1 / (rel * sec), delta=1e-6 / (rel * sec))
        # Least-squares slope of log relMSE against log spp: -1 for an unbiased estimator of
        # independent samples
        lx = [math.log(int(r["spp"])) for r in rows]
        ly = [math.log(float(r["rel_mse"])) for r in rows]
        mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
        slope = sum((x - mx) * (y - my) for x, y in zip(lx, ly)) / sum((x - mx) ** 2 for x in lx)
        self.assertGreaterEqual(slope, -1.3, rows)
        self.assertLessEqual(slope, -0.7, rows)
        self.assertIn("relMSE slope", p.stdout)
        if HAVE_MPL:
            with open(chart, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def expect_error(self, pattern, *args):
        p = run(*args)
        self.assertEqual(p.returncode, 1, p.stderr)
        errors = [l for l in p.stderr.splitlines() if l.startswith("candela: error:")]
        self.assertEqual(len(errors), 1, p.stderr)
        self.assertIn(pattern, errors[0])

    def test_missing_reference(self):
        self.expect_error("reference not found", SCENE, "--reference", os.path.join(self.tmp.name, "nope.exr"))

    def test_size_mismatch(self):
        self.expect_error("size mismatch", SCENE, "--reference", self.ref, "--width", "16")

    def test_unknown_device(self):
        p = subprocess.run([sys.executable, SCRIPT, SCENE, "--reference", self.ref, "--candela", CANDELA,
                            "--device", "quantum"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.assertEqual(p.returncode, 1)
        self.assertIn("candela: error: no OpenCL device matches --device 'quantum'", p.stderr)

    def test_bad_ladder(self):
        self.expect_error("--spp-ladder", SCENE, "--reference", self.ref, "--spp-ladder", "1,x")


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
