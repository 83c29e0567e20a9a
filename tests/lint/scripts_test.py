"""scripts/ is one toolkit: every Python script is a .py module; the scripts that run candela or read images
do it through the shared module scripts/candela_tools (no other script imports OpenImageIO or runs
`candela render` on its own); no script or test loads another through a file loader; each Python script
compiles and answers --help; and every script path README.md and .ci/run name exists.

Usage: python3 tests/lint/scripts_test.py REPO_ROOT
"""
import os
import py_compile
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(sys.argv[1]) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
SCRIPTS = os.path.join(ROOT, "scripts")
SHARED = os.path.join(SCRIPTS, "candela_tools")

# A file loader: the way a script without a .py name (or outside sys.path) used to be imported
FILE_LOADER = re.compile(r"SourceFileLoader|spec_from_file_location|importlib\.machinery|imp\.load_source|"
                         r"runpy\.run_path")
READS_IMAGES = re.compile(r"^\s*(import OpenImageIO|from OpenImageIO)|\boiiotool\b", re.M)
# `candela render` started by hand: a list literal with "render" after its first element (the binary)
RUNS_CANDELA = re.compile(r"\[[^\]\[]*?,\s*\"render\"\s*[,\]]")
IMPORTS_SHARED = re.compile(r"^\s*(import candela_tools|from candela_tools\b)", re.M)
SCRIPT_PATH = re.compile(r"\bscripts/[\w./-]*[\w-]")


def files_under(folder):
    out = []
    for d, dirs, files in os.walk(folder):
        dirs[:] = sorted(x for x in dirs if x != "__pycache__")
        out += [os.path.join(d, f) for f in sorted(files) if not f.endswith(".pyc")]
    return out


def is_python(path):
    if path.endswith(".py"):
        return True
    with open(path, "rb") as f:
        first = f.readline()
    return first.startswith(b"#!") and b"python" in first


def text(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def rel(path):
    return os.path.relpath(path, ROOT)


PYTHON = [p for p in files_under(SCRIPTS) if is_python(p)]
OUTSIDE_SHARED = [p for p in PYTHON if not p.startswith(SHARED + os.sep)]


class Scripts(unittest.TestCase):
    def test_the_shared_module_is_there(self):
        self.assertTrue(os.path.isfile(os.path.join(SHARED, "__init__.py")))
        self.assertGreater(len(OUTSIDE_SHARED), 10, "the Python scripts were found")

    def test_every_python_script_has_a_py_name(self):
        self.assertEqual([rel(p) for p in PYTHON if not p.endswith(".py")], [])

    def test_python_file_names_are_importable(self):
        bad = [rel(p) for p in PYTHON if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*\.py", os.path.basename(p))]
        self.assertEqual(bad, [])

    def test_no_script_or_test_loads_another_through_a_file_loader(self):
        paths = PYTHON + [p for p in files_under(os.path.join(ROOT, "tests")) if p.endswith(".py")]
        bad = [rel(p) for p in paths if p != os.path.abspath(__file__) and FILE_LOADER.search(text(p))]
        self.assertEqual(bad, [])

    def test_only_the_shared_module_reads_images(self):
        self.assertEqual([rel(p) for p in OUTSIDE_SHARED if READS_IMAGES.search(text(p))], [])

    def test_scripts_that_run_candela_or_read_images_import_the_shared_module(self):
        users = [p for p in OUTSIDE_SHARED if RUNS_CANDELA.search(text(p)) or READS_IMAGES.search(text(p)) or
                 re.search(r"\bct\.", text(p))]
        self.assertEqual([rel(p) for p in users if not IMPORTS_SHARED.search(text(p))], [])
        # The scripts known to do both stay among them: the metric's users
        for name in ("compare/converge.py", "compare/equal_time.py", "compare/vs_cycles.py", "compare/vs_mitsuba.py",
                     "compare/relmse.py", "check/render_samples.py", "bench/cold.py"):
            self.assertRegex(text(os.path.join(SCRIPTS, name)), IMPORTS_SHARED, name)

    def test_candela_render_runs_through_the_shared_module(self):
        self.assertEqual([rel(p) for p in OUTSIDE_SHARED if RUNS_CANDELA.search(text(p))], [])
        self.assertRegex(text(os.path.join(SHARED, "__init__.py")), RUNS_CANDELA)

    def test_every_python_script_compiles(self):
        with tempfile.TemporaryDirectory() as tmp:
            for p in PYTHON:
                with self.subTest(script=rel(p)):
                    py_compile.compile(p, cfile=os.path.join(tmp, "x.pyc"), doraise=True)

    def test_every_command_line_script_answers_help(self):
        try:
            import numpy  # noqa: F401
            import OpenImageIO  # noqa: F401
        except ImportError:
            self.skipTest("numpy or OpenImageIO's Python module is missing (python3-numpy, python3-openimageio)")
        clis = [p for p in OUTSIDE_SHARED if "argparse" in text(p)]
        self.assertGreater(len(clis), 8)
        for p in clis:
            with self.subTest(script=rel(p)):
                r = subprocess.run([sys.executable, p, "--help"], capture_output=True, text=True, timeout=120)
                self.assertEqual(r.returncode, 0, r.stderr[-2000:])
                self.assertIn("usage:", r.stdout)


class NamedPaths(unittest.TestCase):
    def check(self, name):
        path = os.path.join(ROOT, name)
        found = sorted(set(SCRIPT_PATH.findall(text(path))))
        self.assertTrue(found, "%s names no script" % name)
        missing = [s for s in found if not os.path.exists(os.path.join(ROOT, s))]
        self.assertEqual(missing, [], "%s names scripts that are not there" % name)

    def test_readme_names_scripts_that_exist(self):
        self.check("README.md")

    def test_ci_runs_scripts_that_exist(self):
        self.check(os.path.join(".ci", "run"))
        ci = text(os.path.join(ROOT, ".ci", "run"))
        for s in ("scripts/fuzz", "scripts/test"):
            self.assertIn(s, ci)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
