#!/usr/bin/python3
"""The rows of scripts/bench/bench.sh: one JSON object per scene and device from its renders' statistics, and
the ways bench.sh prints or records them.

  bench_rows.py row NAME DEVICE COMMIT TMP BINARY KERNEL_DIR   one JSON line from TMP/{run,cold,cached}.json
                                                               (and TMP/time.txt for the peak RSS of binaries
                                                               whose --stats lack it)
  bench_rows.py csv | table                                    JSON lines on stdin as CSV or as the table
  bench_rows.py record COMMAND                                 JSON lines on stdin into docs/figures/results.json
"""
import csv
import json
import os
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402


def row(name, dev, commit, tmp, binary, kernel_dir):
    def load(f):
        with open(os.path.join(tmp, f)) as h:
            return json.load(h)
    run, cold, cached = load("run.json"), load("cold.json"), load("cached.json")
    rss = run.get("peak_rss_bytes", 0)
    if not rss:  # a binary from before --stats had it
        for line in open(os.path.join(tmp, "time.txt")):
            if "Maximum resident set size" in line:
                rss = int(line.split(":")[1]) * 1024
    tris = run["triangles"]
    return {
        "scene": name, "device": dev, "triangles": tris, "width": run["width"], "spp": run["spp"],
        "max_depth": run["max_depth"], "seconds": round(run["seconds"], 4),
        "samples_per_second": round(run["samples_per_second"]),
        "bvh_build_seconds": round(run["bvh_build_seconds"], 4),
        "bvh_triangles_per_second": round(tris / max(run["bvh_build_seconds"], 1e-9)),
        "kernel_build_cold_seconds": round(cold["kernel_build_seconds"], 3),
        "kernel_cold_from_cache": cold["kernel_from_cache"],
        "kernel_build_cached_seconds": round(cached["kernel_build_seconds"], 3),
        "kernel_from_cache": cached["kernel_from_cache"],
        "scene_device_bytes": run["scene_device_bytes"],
        "device_bytes_per_triangle": round(run["scene_device_bytes"] / max(tris, 1), 1),
        "peak_rss_bytes": rss, "peak_rss_bytes_per_triangle": round(rss / max(tris, 1), 1),
        "bvh_sah_cost": run.get("bvh_sah_cost"), "bvh_threads": run.get("bvh_threads"), "commit": commit,
        "binary": binary, "kernel_dir": kernel_dir,
        "time": time.strftime("%Y-%m-%dT%H:%M:%S"), "device_name": run["device"]}


def write_csv(rows):
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    w = csv.DictWriter(sys.stdout, keys)
    w.writeheader()
    w.writerows(rows)


def table(lines):
    print("%-12s %-8s %8s %4s %8s %10s %7s %8s %8s %8s %6s %7s" % ("scene", "device", "tris", "spp", "Msamp/s",
          "bvh_s", "Mtri/s", "kcold_s", "kcache_s", "B/tri", "RSS_MB", ""))
    for line in lines:
        if not line.strip():
            continue
        r = json.loads(line)
        if "error" in r:
            print("%-12s %-8s error: %s" % (r["scene"], r["device"], r["error"]))
            continue
        print("%-12s %-8s %8d %4d %8.3f %10.3f %7.2f %8.2f %8.2f %8.1f %6.0f" % (
            r["scene"][:12], r["device"], r["triangles"], r["spp"], r["samples_per_second"] / 1e6,
            r["bvh_build_seconds"], r["bvh_triangles_per_second"] / 1e6, r["kernel_build_cold_seconds"],
            r["kernel_build_cached_seconds"], r["device_bytes_per_triangle"], r["peak_rss_bytes"] / 2 ** 20))
        sys.stdout.flush()


def record(rows, command):
    """One figure per scene and device: "<scene>-bench-<device>" (the scene's short name, as result_key)."""
    for r in rows:
        if "error" in r:
            continue
        figure = ("%.3f Msamples/s (%d spp, %dx%d, max depth %d); BVH %.3f s (%.2f M triangles/s); kernel build "
                  "%.2f s cold, %.3f s cached; peak RSS %.0f MB" % (
                      r["samples_per_second"] * 1e-6, r["spp"], r["width"], r["width"], r["max_depth"],
                      r["bvh_build_seconds"], r["bvh_triangles_per_second"] * 1e-6, r["kernel_build_cold_seconds"],
                      r["kernel_build_cached_seconds"], r["peak_rss_bytes"] / 2 ** 20))
        ct.record_result(ct.result_key(r["scene"], "bench-" + r["device"]), figure, command,
                         "%s, %s" % (ct.cpu_description(), r["device_name"]))


def main(argv):
    if len(argv) == 7 and argv[0] == "row":
        print(json.dumps(row(*argv[1:])))
    elif argv == ["csv"]:
        write_csv([json.loads(l) for l in sys.stdin if l.strip()])
    elif argv == ["table"]:
        table(sys.stdin)
    elif len(argv) == 2 and argv[0] == "record":
        record([json.loads(l) for l in sys.stdin if l.strip()], argv[1])
    else:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
