#!/usr/bin/python3
"""The glTF files beside the checkout, rendered with the default command, pass the checks of
scripts/render-samples: the Khronos sample assets (../shared/gltf-samples) and the glTF
exporter's regression scenes (../shared/gltf-blender-io/roundtrip). Each asset must render
without error and without a dropped sample, not black, not a white wall, and in view (the
script's --check; an empty scene must be refused with the "no triangles" message).

Run by ctest: sample_assets_test.py CANDELA_BINARY SOURCE_DIR. Small renders (64 px wide,
4 spp) keep it to a few seconds per asset on PoCL; a folder that is not there skips its test.
"""

import json
import os
import subprocess
import sys
import tempfile
import unittest

BINARY = sys.argv[1] if len(sys.argv) > 1 else ""
SOURCE = sys.argv[2] if len(sys.argv) > 2 else os.path.dirname(os.path.dirname(os.path.dirname(__file__)))
SCRIPT = os.path.join(SOURCE, "scripts", "check", "render_samples.py")
sys.path.insert(0, os.path.join(SOURCE, "scripts"))
import candela_tools  # noqa: E402  (the sample assets' folder)

try:
    import numpy  # noqa: F401
    import OpenImageIO  # noqa: F401
    HAVE_DEPS = True
except ImportError:
    HAVE_DEPS = False


def gltf_files(folder):
    n = 0
    for d, dirs, files in os.walk(folder):
        dirs[:] = [x for x in dirs if not x.startswith("_")]
        n += sum(1 for f in files if f.lower().endswith((".gltf", ".glb")))
    return n


@unittest.skipUnless(HAVE_DEPS, "numpy or OpenImageIO's Python module is missing (python3-numpy, python3-openimageio)")
class SampleAssets(unittest.TestCase):
    def check_folder(self, folder):
        if not os.path.isdir(folder):
            self.skipTest(folder + " is not there")
        expected = gltf_files(folder)
        self.assertGreater(expected, 0, "no glTF files under " + folder)
        with tempfile.TemporaryDirectory(prefix="candela-assets-") as out:
            run = subprocess.run([sys.executable, SCRIPT, folder, "--binary", BINARY, "--out", out, "--width", "64",
                                  "--spp", "4", "--timeout", "600", "--check"], capture_output=True, text=True)
            with open(os.path.join(out, "samples.jsonl")) as f:
                rows = [json.loads(line) for line in f if line.strip()]
        failed = ["%s: %s %s" % (r["asset"], ", ".join(r["failures"]), r.get("error") or "") for r in rows if not r["ok"]]
        self.assertEqual(failed, [], run.stdout[-4000:] + run.stderr[-2000:])
        self.assertEqual(len(rows), expected, "every file rendered once")
        self.assertEqual(run.returncode, 0, run.stdout[-4000:] + run.stderr[-2000:])

    def test_khronos_sample_assets_pass_the_default_command_checks(self):
        self.check_folder(candela_tools.samples_folder())

    def test_exporter_roundtrip_scenes_pass_the_default_command_checks(self):
        samples = candela_tools.samples_folder()
        self.check_folder(os.path.join(os.path.dirname(samples), "gltf-blender-io", "roundtrip"))


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
