#!/usr/bin/env python3
"""The compiles of scripts/gpu/compile.sh, which installs the tools, builds the program text and runs this:

    compile_kernels.py ROOT [--quick] [--out FILE] [--markdown] [--jobs N] [--ci]
"""
import concurrent.futures, json, os, re, shutil, subprocess, sys, time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import candela_tools as ct  # noqa: E402

root, args = sys.argv[1], sys.argv[2:]
quick = "--quick" in args
markdown = "--markdown" in args
usage = "usage: scripts/gpu/compile.sh [--quick] [--out FILE] [--markdown] [--jobs N] [--ci]"


def value(flag, default):
    if flag not in args:
        return default
    i = args.index(flag)
    if i + 1 >= len(args):
        sys.exit(usage)
    return args[i + 1]


out_file = value("--out", None)
jobs = value("--jobs", str(os.cpu_count() or 2))
if not jobs.isdigit() or int(jobs) < 1:
    sys.exit(usage)
jobs = int(jobs)
for i, a in enumerate(args):
    if a not in ("--quick", "--markdown", "--out", "--jobs", "--ci") and (i == 0 or args[i - 1] not in ("--out", "--jobs")):
        sys.exit(usage)
work = os.path.join(root, "build", "gpu-compile")
clc = os.path.join(work, "libclc-19")
build = os.path.join(root, "build")
KERNEL = "render_paths"
start = time.time()

# Targets: (name, triple, cpu)
TARGETS = [("gfx90a", "amdgcn-amd-amdhsa", "gfx90a"), ("gfx1030", "amdgcn-amd-amdhsa", "gfx1030"),
           ("sm_80", "nvptx64-nvidia-cuda", "sm_80"), ("sm_90", "nvptx64-nvidia-cuda", "sm_90")]
PTX_ISA = "+ptx78"  # PTX 7.8 (CUDA 11.8): the first with sm_90; pinned, not the local toolkit's
# ptxas: CANDELA_PTXAS (a path, or "none"), else PATH's, else the CUDA toolkit's default place
ptxas = os.environ.get("CANDELA_PTXAS") or shutil.which("ptxas") or "/usr/local/cuda/bin/ptxas"
ptxas = ptxas if ptxas != "none" and os.access(ptxas, os.X_OK) else None
TOOLS = {"clang": subprocess.run(["clang-19", "--version"], capture_output=True, text=True).stdout.splitlines()[0],
         "libclc": open(os.path.join(clc, "version")).read().strip(),
         "ptxas": ptxas and next((l for l in subprocess.run([ptxas, "--version"], capture_output=True, text=True).stdout.splitlines()
                                  if "release" in l), "ptxas")}
git = ["git", "-C", root]
COMMIT = subprocess.run(git + ["rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
if subprocess.run(git + ["status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True).stdout.strip():
    COMMIT += "+changes"


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def diagnostics(text):
    """The error and warning lines of a tool's output (clang, opt, llc, ptxas)."""
    return [l for l in text.splitlines() if re.search(r"(^|\s|:)(fatal error|error|warning)\s*:", l, re.I)]


# The program as the host builds it
for d in ("ir", "stats"):
    shutil.rmtree(os.path.join(work, d), ignore_errors=True)
    os.makedirs(os.path.join(work, d))
program = os.path.join(work, "program.cl")
with open(program, "w") as f:
    subprocess.run([os.path.join(build, "tests", "candela_kernel_source")], stdout=f, check=True)

# GNU C's type operators, which clang accepts in OpenCL C without any warning (-Wgnu and
# -pedantic do not cover the reserved spellings): a front end that is not clang or GCC rejects them
with open(program) as f:
    gnu = sorted({f"line {n}: {m.group(0)}" for n, l in enumerate(f, 1)
                  for m in re.finditer(r"\b(__typeof__|__typeof|typeof|__auto_type)\b", l)})
if gnu:
    sys.exit("candela: GNU extensions in the program text (build/gpu-compile/program.cl): " + ", ".join(gnu))

# The -cl- options the renderer passes (host/render/renderer.cpp)
with open(os.path.join(root, "host", "render", "renderer.cpp")) as f:
    cl_options = sorted(set(re.findall(r'"(-cl-[\w.=-]+)', f.read())))
if not any(o.startswith("-cl-std=") for o in cl_options):
    sys.exit("candela: no -cl-std option found in host/render/renderer.cpp")

# Variants: the kernel options of each shipped scene and of --generic, from render --stats
scenes = sorted(os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(os.path.join(root, "scenes"))
                for f in fs if f.endswith(".gltf"))
env = dict(os.environ, CANDELA_CACHE_DIR=os.path.join(work, "kernel-cache"))


def scene_options(job):
    scene, generic = job
    name = "generic" if generic else os.path.splitext(os.path.basename(scene))[0]
    stem = os.path.join(work, "stats", "generic" if generic else os.path.splitext(scene)[0].replace("/", "-"))
    stats = stem + ".json"
    try:
        s = ct.render(os.path.join(root, scene), stem + ".exr", ["--spp", "1", "--width", "8", "-q"] +
                      (["--generic"] if generic else []), binary=os.path.join(build, "candela"), stats=stats,
                      env=env).stats
    except ct.RenderError as e:
        sys.exit(f"candela: render {scene} failed:\n{e.stderr}")
    sampler = " -DCD_SAMPLER_SOBOL=1" if s["sampler"] == "sobol" else " -DCD_SAMPLER_SOBOL=0"
    return name, scene, s["kernel_features"] + sampler


with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
    found = list(pool.map(scene_options, [(s, False) for s in scenes] + [(scenes[0], True)]))
variants = {}  # options -> {name (its first scene's, or generic), scenes}
for name, scene, options in found:
    v = variants.setdefault(options, {"name": name, "scenes": [], "options": options})
    if name == "generic":
        v["name"] = name
    else:
        v["scenes"].append(scene)
variants = list(variants.values())
for v in variants:
    if sum(w["name"] == v["name"] for w in variants) > 1:
        v["name"] = os.path.splitext(v["scenes"][0])[0].replace("scenes/", "").replace("/", "-")
for v in variants:
    v["features"] = [m.lower() for m in re.findall(r"-DCD_FEATURE_(\w+)=1", v["options"])]
smallest = min(variants, key=lambda v: len(v["features"]))["name"]
measured = {"generic", smallest} if quick else {v["name"] for v in variants}


def amdgpu_shape(asm):
    """Per function: the resource comments of llc's AMDGPU asm; per kernel: its metadata."""
    funcs, cur, info = {}, None, None
    for line in asm.splitlines():
        m = re.search(r"; -- Begin function (\S+)", line)
        if m:
            cur = m.group(1)
        elif re.match(r"; (Kernel|Function) info:", line):
            info = funcs.setdefault(cur, {})
        elif info is not None:
            m = re.match(r"; (\w+)\s*[:=]\s*(\d+)\s*$", line)
            if m:
                info[m.group(1)] = int(m.group(2))
            elif not line.startswith(";"):
                info = None
    meta, entry = {}, None
    body = asm.split(".amdgpu_metadata", 1)[1] if ".amdgpu_metadata" in asm else ""
    for line in body.splitlines():
        if re.match(r"  - \.", line):
            entry = {}
        m = re.match(r"  [ -] \.([\w]+):\s+(\S+)", line)
        if entry is not None and m:
            entry[m.group(1)] = m.group(2)
            if m.group(1) == "name":
                meta[m.group(2)] = entry
    return funcs, meta


def ptx_shape(ptx):
    """Per function: .local depot bytes and callees; cumulative .local bytes of each entry."""
    funcs = {}
    for m in re.finditer(r"^(?:\.visible\s+|\.weak\s+)?\.(entry|func)\s+(?:\([^)]*\)\s*)?(\w+)\s*\((.*?)^\}", ptx, re.M | re.S):
        body = m.group(3)
        depot = sum(int(x) for x in re.findall(r"__local_depot\d+\[(\d+)\]", body))
        calls = set(re.findall(r"\bcall(?:\.uni)?\s*(?:\([^)]*\)\s*,)?\s*(\w+)\s*,", body))
        funcs[m.group(2)] = {"entry": m.group(1) == "entry", "local": depot, "calls": calls}

    def total(name, seen=()):
        f = funcs.get(name)
        if f is None or name in seen:
            return 0
        return f["local"] + max([total(c, seen + (name,)) for c in f["calls"]] or [0])

    for name, f in funcs.items():
        f["local_total"] = total(name)
    return funcs


def ptxas_shape(text):
    """Per entry: registers, stack frame, spill stores and loads (ptxas -v)."""
    out, cur = {}, None
    for line in text.splitlines():
        m = re.search(r"Function properties for (\w+)", line)
        if m:
            cur = m.group(1)
            continue
        m = re.search(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads", line)
        if m and cur:
            out.setdefault(cur, {}).update(stack=int(m.group(1)), spill_stores=int(m.group(2)), spill_loads=int(m.group(3)))
        m = re.search(r"Used (\d+) registers", line)
        if m and cur:
            out.setdefault(cur, {})["registers"] = int(m.group(1))
            m = re.search(r"(\d+) bytes cumulative stack size", line)
            if m:
                out[cur]["cumulative_stack"] = int(m.group(1))
    return out


def warps_per_sm(registers, group=64):
    """Resident warps per SM that the register file allows (sm_80/sm_90: 64K registers, 64
    warps; registers allocated per warp in units of 256), in whole work-groups of `group`."""
    per_warp = -(-registers * 32 // 256) * 256
    warps = min(64, 65536 // per_warp)
    return warps // (group // 32) * (group // 32)


def compile_one(job):
    v, (tname, triple, cpu) = job
    base = os.path.join(work, "ir", f"{v['name']}.{tname}")
    amd = triple.startswith("amdgcn")
    r = {"variant": v["name"], "target": triple, "cpu": cpu, "kernel": KERNEL, "ok": True, "diagnostics": []}
    timings = {}

    def step(name, cmd):
        t = time.time()
        p = run(cmd)
        timings[name] = round(time.time() - t, 2)
        diags = diagnostics(p.stdout + p.stderr)
        if p.returncode != 0 and not diags:
            diags = [f"{name} failed (exit {p.returncode}): {(p.stderr or p.stdout).strip()[-400:]}"]
        r["diagnostics"] += [f"{name}: {d}" for d in diags]
        r["ok"] = r["ok"] and not diags and p.returncode == 0
        return p

    # Front end: OpenCL C 1.2, the variant's options, libclc linked as builtins (no LLVM passes yet)
    # -Wkeyword-macro, -Wgnu, -pedantic: a macro named like a keyword, GNU extensions (statement
    # expressions, ...) and other non-standard C are what another OpenCL front end may reject
    fe = ["clang-19", "-x", "cl"] + cl_options + ["-Wkeyword-macro", "-Wgnu", "-pedantic", "-Xclang", "-finclude-default-header", "-O3",
          "-Xclang", "-disable-llvm-passes", "-nogpulib", "-target", triple, "-emit-llvm", "-S",
          "-Xclang", "-mlink-builtin-bitcode", "-Xclang", os.path.join(clc, triple + ".bc")]
    fe += ["-mcpu=" + cpu] if amd else ["-march=" + cpu, "--cuda-path=/nonexistent", "-Xclang", "-target-feature", "-Xclang", PTX_ISA]
    step("clang", fe + v["options"].split() + ["-o", base + ".ll", program])
    if not r["ok"] or v["name"] not in measured:
        r["measured"] = False
        r["seconds"] = timings
        return r
    r["measured"] = True
    with open(base + ".ll") as f:
        kernels = re.findall(r"^define [^@]*@(\w+)\(.*!kernel_arg_addr_space", f.read(), re.M)
    # Whole program, as a driver links it: every function but the kernels internal, then -O3
    step("opt", ["opt-19", "-S", "-passes=internalize,default<O3>", "-internalize-public-api-list=" + ",".join(kernels),
                 base + ".ll", "-o", base + ".opt.ll"])
    if not r["ok"]:
        return r
    with open(base + ".opt.ll") as f:
        ir = f.read()
    unresolved = sorted(set(re.findall(r"^declare [^@]*@(\w+)\(", ir, re.M)) - set(re.findall(r"^declare [^@]*@(llvm\.[\w.]+)\(", ir, re.M)))
    if unresolved:
        r["ok"] = False
        r["diagnostics"].append("unresolved builtins (cost hidden): " + " ".join(unresolved))
    asm = base + (".s" if amd else ".ptx")
    step("llc", ["llc-19", "-O3", "-mtriple=" + triple, "-mcpu=" + cpu] + ([] if amd else ["-mattr=" + PTX_ISA]) + [base + ".opt.ll", "-o", asm])
    if not r["ok"]:
        return r
    with open(asm) as f:
        text = f.read()
    if amd:
        funcs, meta = amdgpu_shape(text)
        k, m = funcs.get(KERNEL, {}), meta.get(KERNEL, {})
        r.update(vgprs=k.get("NumVgprs"), agprs=k.get("NumAgprs"), sgprs=k.get("NumSgprs"),
                 scratch_bytes=k.get("ScratchSize"), sgpr_spills=int(m.get("sgpr_spill_count", 0)),
                 vgpr_spills=int(m.get("vgpr_spill_count", 0)), occupancy=k.get("Occupancy"),
                 wave_size=int(m.get("wavefront_size", 0)) or None, dynamic_stack=m.get("uses_dynamic_stack") == "true",
                 code_bytes=k.get("codeLenInByte"))
        r["functions"] = {n: {"vgprs": f.get("TotalNumVgprs", f.get("NumVgprs")), "scratch_bytes": f.get("ScratchSize")}
                          for n, f in funcs.items() if n not in meta}
        r["other_kernels"] = {n: {"vgprs": funcs[n].get("TotalNumVgprs"), "sgprs": funcs[n].get("NumSgprs"),
                                  "scratch_bytes": funcs[n].get("ScratchSize"), "occupancy": funcs[n].get("Occupancy")}
                              for n in kernels if n != KERNEL and n in funcs}
    else:
        funcs = ptx_shape(text)
        k = funcs.get(KERNEL, {})
        r.update(ptx_local_bytes=k.get("local_total"), registers=None, stack_bytes=None, spill_stores=None,
                 spill_loads=None, warps_per_sm=None)
        r["functions"] = {n: {"local_bytes": f["local"]} for n, f in funcs.items() if not f["entry"]}
        if ptxas:
            p = step("ptxas", [ptxas, "-v", "--gpu-name", cpu, asm, "-o", base + ".cubin"])
            e = ptxas_shape(p.stdout + p.stderr)
            ke = e.get(KERNEL, {})
            r.update(registers=ke.get("registers"), stack_bytes=ke.get("cumulative_stack", ke.get("stack")),
                     spill_stores=ke.get("spill_stores"), spill_loads=ke.get("spill_loads"))
            if r["registers"]:
                r["warps_per_sm"] = warps_per_sm(r["registers"])
            r["other_kernels"] = {n: {"registers": e[n].get("registers"), "stack_bytes": e[n].get("stack")}
                                  for n in kernels if n != KERNEL and n in e}
    r["seconds"] = timings
    return r


# Longest first: the generic variant, NVPTX (ptxas) before AMDGPU
order = sorted(((v, t) for v in variants for t in TARGETS),
               key=lambda j: (j[0]["name"] not in measured, j[0]["name"] != "generic", j[1][1].startswith("amdgcn")))
with concurrent.futures.ThreadPoolExecutor(jobs) as pool:
    results = list(pool.map(compile_one, order))
rank = {(v["name"], t[0]): (i, j) for i, v in enumerate(variants) for j, t in enumerate(TARGETS)}
results.sort(key=lambda r: rank[(r["variant"], r["cpu"])])
for r in results:
    v = next(v for v in variants if v["name"] == r["variant"])
    r.update(scenes=v["scenes"], options=" ".join(cl_options) + " " + v["options"], commit=COMMIT,
             date=time.strftime("%Y-%m-%d"), tools=TOOLS)

lines = [json.dumps(r) for r in results]
if out_file:
    with open(out_file, "a") as f:
        f.write("".join(l + "\n" for l in lines))


def cell(x):
    return "-" if x is None else str(x)


if markdown:
    print("| variant | scenes | features on |\n|---|---|---|")
    for v in variants:
        print(f"| {v['name']} | {', '.join(os.path.basename(s)[:-5] for s in v['scenes']) or '(any, --generic)'} | "
              f"{', '.join(v['features']) or 'none'} |")
    print("\n| variant | target | VGPRs | AGPRs | SGPRs | scratch B/lane | spills SGPR/VGPR | waves/SIMD | wave |\n"
          "|---|---|---|---|---|---|---|---|---|")
    for r in results:
        if r["target"].startswith("amdgcn") and r.get("vgprs") is not None:
            print(f"| {r['variant']} | {r['cpu']} | {r['vgprs']} | {cell(r['agprs'])} | {r['sgprs']} | {r['scratch_bytes']} | "
                  f"{r['sgpr_spills']}/{r['vgpr_spills']} | {r['occupancy']} | {r['wave_size']} |")
    print("\n| variant | target | registers | stack B | spill stores/loads B | PTX .local B | warps/SM |\n"
          "|---|---|---|---|---|---|---|")
    for r in results:
        if r["target"].startswith("nvptx") and r.get("ptx_local_bytes") is not None:
            print(f"| {r['variant']} | {r['cpu']} | {cell(r['registers'])} | {cell(r['stack_bytes'])} | "
                  f"{cell(r['spill_stores'])}/{cell(r['spill_loads'])} | {r['ptx_local_bytes']} | {cell(r['warps_per_sm'])} |")
else:
    print("\n".join(lines))

failed = [r for r in results if not r["ok"]]
n_measured = sum(r.get("measured", False) for r in results)
print(f"candela: {len(variants)} variants x {len(TARGETS)} targets compiled, {n_measured} measured"
      f"{'' if ptxas else ' (no ptxas: PTX .local bytes only)'}, {time.time() - start:.0f}s", file=sys.stderr)
if failed:
    where = {}  # each diagnostic once, with the compiles that raised it
    for r in failed:
        for d in r["diagnostics"]:
            where.setdefault(d, []).append(f"{r['variant']}/{r['cpu']}")
    for d, w in where.items():
        print(f"candela: {d}\n  in {len(w)} of {len(results)} compiles: {' '.join(w)}", file=sys.stderr)
    print(f"candela: {len(failed)} compiles with errors or warnings: what a GPU driver would reject or warn about",
          file=sys.stderr)
    sys.exit(1)
