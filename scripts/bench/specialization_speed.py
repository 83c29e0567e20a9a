#!/usr/bin/python3
"""The speed runs and tables of scripts/bench/specialization.sh, which has rendered each scene's cold and cached
kernel builds into OUT:

    specialization_speed.py OUT ROUNDS DEVICE WIDTH SPP SCENE...
"""
import json, statistics, sys, os, resource
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402
out, rounds, dev, width, spp, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), sys.argv[6:]
def cpu_of(scene, options, env):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    ct.render(scene, out + "/x.exr", options, binary="./build/candela", stats=out + "/speed.json", env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
def speed_run(scene, name, v):
    env = dict(os.environ, CANDELA_CACHE_DIR="%s/%s-%s/candela" % (out, name, v),
               POCL_CACHE_DIR="%s/%s-%s/pocl" % (out, name, v), MESA_SHADER_CACHE_DIR="%s/%s-%s/mesa" % (out, name, v))
    base = ["--width", str(width), "--device", dev, "-q"] + (["--generic"] if v == "generic" else [])
    # The CPU time of `more` samples per pixel must stand out of the timer's resolution and the
    # noise: where the difference is under 0.2 s, four times the samples, up to 64 times
    more = spp
    lo = cpu_of(scene, base + ["--spp", "4"], env)  # the fixed cost, measured once per run
    while True:
        hi = cpu_of(scene, base + ["--spp", str(4 + more)], env)
        if hi - lo >= 0.2 or more >= 64 * spp:
            break
        more *= 4
    pixels = json.load(open(out + "/speed.json"))
    pixels = pixels["width"] * pixels["height"]
    return more * pixels / (hi - lo) if hi - lo > 0.02 else float("nan")  # nan: not resolved
speeds = {}
for scene in scenes:
    name = os.path.basename(scene)[:-5]
    for r in range(rounds):  # alternating, and which goes first alternates too
        for v in (("specialized", "generic") if r % 2 == 0 else ("generic", "specialized")):
            speeds.setdefault((name, v), []).append(speed_run(scene, name, v))
def load(p): return json.load(open(os.path.join(out, p)))
def wall(p): return int(open(os.path.join(out, p)).read()) * 1e-9
print("| scene | kernel | build cold s | first run wall s | build cached s | M samples per CPU-s (median of %d) |" % rounds)
print("|---|---|---|---|---|---|")
ratios = {}
for scene in scenes:
    name = os.path.basename(scene)[:-5]
    speed = {}
    for v in ("specialized", "generic"):
        cold, cached = load("%s-%s-cold.json" % (name, v)), load("%s-%s-cached.json" % (name, v))
        assert cached["kernel_from_cache"], cached
        speed[v] = statistics.median(speeds[(name, v)])
        print("| %s | %s | %.2f | %.2f | %.3f | %.3f |" % (name, v, cold["kernel_build_seconds"],
              wall("%s-%s-cold.wall" % (name, v)), cached["kernel_build_seconds"], speed[v] / 1e6))
        if v == "specialized":
            ratios[name] = [cold["kernel_build_seconds"], wall("%s-%s-cold.wall" % (name, v))]
        else:
            ratios[name] += [cold["kernel_build_seconds"], wall("%s-%s-cold.wall" % (name, v))]
    ratios[name].append(speed["specialized"] / speed["generic"])
print()
print("| scene | generic / specialized cold build | generic / specialized first-run wall | specialized / generic speed |")
print("|---|---|---|---|")
for name, (bs, ws, bg, wg, sp) in ratios.items():
    print("| %s | %.2f | %.2f | %.2f |" % (name, bg / bs, wg / ws, sp))
