#!/usr/bin/python3
"""Time to the first image with cold caches: what a new user waits for.

Usage: scripts/bench/cold.py [--rounds N] [--device DEV] [--width W] --binary A [--binary B ...]
                          SCENE [SCENE ...]

Each round gives every binary (in turn, the order alternating between rounds) a fresh,
empty kernel cache (CANDELA_CACHE_DIR) and PoCL cache (POCL_CACHE_DIR) and renders the
scenes one after the other into them with `candela render SCENE --spp 1 --width W`: the
first scene meets empty caches (the first render after installing), each later one finds
what the renders before it left (a new scene on a machine in use: its kernel variant is
new, the rest may be cached). Prints one line per round, binary and scene, then a markdown
table of the median wall seconds of each (whole process, from start to exit).
The machines are shared: compare binaries within one run, not across runs.
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
p.add_argument("--rounds", type=int, default=3)
p.add_argument("--device", default="pocl")
p.add_argument("--width", type=int, default=64)
p.add_argument("--binary", action="append", required=True, help="a candela executable (repeat to compare)")
p.add_argument("scenes", nargs="+")
a = p.parse_args()
for s in a.scenes:
    if not os.path.isfile(s):
        sys.exit(f"bench-cold: no scene file {s}")
for b in a.binary:
    if not os.access(b, os.X_OK):
        sys.exit(f"bench-cold: {b} is not an executable")

walls = {(b, s): [] for b in a.binary for s in a.scenes}
print("#", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip(), flush=True)
for r in range(a.rounds):
    order = a.binary if r % 2 == 0 else list(reversed(a.binary))
    for b in order:
        work = tempfile.mkdtemp(prefix="candela-bench-cold-")
        env = dict(os.environ, CANDELA_CACHE_DIR=os.path.join(work, "candela"), POCL_CACHE_DIR=os.path.join(work, "pocl"))
        try:
            for s in a.scenes:
                try:
                    wall = ct.render(s, os.path.join(work, "x.exr"), ["--spp", "1", "--width", a.width, "--device",
                                                                      a.device, "-q"], binary=b, env=env).wall
                except ct.RenderError as e:
                    sys.exit(f"bench-cold: {b} render {s} failed:\n{e.stderr}")
                walls[(b, s)].append(wall)
                print(f"round {r + 1} {b} {s}: {wall:.2f} s", flush=True)
        finally:
            shutil.rmtree(work, ignore_errors=True)

print()
print("| scene (in order; the first with empty caches) | " + " | ".join(a.binary) + " |")
print("|---" * (len(a.binary) + 1) + "|")
for s in a.scenes:
    cells = []
    for b in a.binary:
        w = walls[(b, s)]
        cells.append(f"{statistics.median(w):.2f} ({', '.join(f'{x:.2f}' for x in w)})")
    print(f"| {s} | " + " | ".join(cells) + " |")
