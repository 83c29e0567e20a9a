#!/usr/bin/env python3
"""Pack candela's programs with the shared libraries they load into one .tar.xz that runs on
another x86-64 Linux machine without Debian's packages (a GPU machine with only its driver).

    scripts/gpu/portable_bundle.py OUT.tar.xz [PROGRAM...]   (default: build/candela build/tests/candela_tests)

The archive holds bin/ (the programs), lib/ (their libraries, found with ldd), fallback/
(this machine's libstdc++ and libgcc_s, for a machine whose own are older) and run (a
wrapper: `run candela devices`). glibc stays the target's (it must be at least this
machine's version). Libraries that OpenImageIO links for formats candela never reads
(video, DICOM, camera raw, HEIF, OpenCV, OpenColorIO, FreeType) are replaced by stubs that
define only the symbols the kept libraries import; a stub function does nothing and returns
a pointer to zeros (OpenImageIO calls some at load: version queries, static objects'
constructors), and names itself on stderr when CANDELA_BUNDLE_TRACE is set; that keeps the archive near 25 MB instead of 350. The OpenCL ICD loader is
packed; the target's vendor driver is found through OCL_ICD_VENDORS (see scripts/gpu/check.sh).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SYSTEM = re.compile(r"^(libc|libm|libpthread|libdl|librt|ld-linux-x86-64|libresolv|libutil)\.so")
FALLBACK = re.compile(r"^(libstdc\+\+|libgcc_s)\.so")
STUB = re.compile(r"^(libopencv_|libdcm|liboflog|libofstd|libavcodec|libavformat|libavutil|libswscale|"
                  r"libheif|libraw_r|libOpenColorIO|libfreetype)")


def run(*cmd):
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def needed(path):
    return re.findall(r"NEEDED.*\[(.*)\]", run("readelf", "-d", path))


def ldd_paths(program):
    paths = {}
    for line in run("ldd", program).splitlines():
        m = re.match(r"\s*(\S+) => (\S+)", line)
        if m:
            paths[m.group(1)] = m.group(2)
    return paths


def dyn_symbols(path, defined):
    """{name@version or name: (type, size)} of the dynamic symbol table"""
    args = ["nm", "-D", "-S", "--defined-only" if defined else "--undefined-only", path]
    out = {}
    for line in run(*args).splitlines():
        parts = line.split()
        if defined and len(parts) >= 3:
            size = int(parts[1], 16) if len(parts) == 4 else 8
            out[parts[-1]] = (parts[-2], size)
        elif not defined and parts:
            out[parts[-1]] = ("U", 0)
    return out


def base_name(sym):
    return sym.split("@")[0]


def version_of(sym):
    return sym.split("@")[-1] if "@" in sym else None


def make_stub(soname, real_path, wanted, workdir, libdir):
    """A library named soname defining the symbols in `wanted` that real_path defines"""
    defined = {base_name(s): (s, t) for s, t in dyn_symbols(real_path, True).items()}
    lines = ["#include <stdio.h>", "#include <stdlib.h>",
             "static char zeros[4096];",
             "static long stub(const char* s) {",
             '  if (getenv("CANDELA_BUNDLE_TRACE")) fprintf(stderr, "candela bundle: stub %s (' + soname + ')\\n", s);',
             "  return (long)zeros;", "}"]
    versions = {}
    for i, name in enumerate(sorted(wanted)):
        if name not in defined:
            continue
        full, (kind, size) = defined[name]
        ver = version_of(full)
        versions.setdefault(ver, []).append(name)
        if kind in "TtWwi":
            lines.append(f'long f{i}(void) __asm__("{name}"); long f{i}(void) {{ return stub("{name}"); }}')
        else:
            lines.append(f'char d{i}[{max(size, 1)}] __asm__("{name}");')
    src = os.path.join(workdir, soname + ".c")
    with open(src, "w") as f:
        f.write("\n".join(lines) + "\n")
    script = os.path.join(workdir, soname + ".map")
    with open(script, "w") as f:
        for ver, names in versions.items():
            if ver:
                f.write(f"{ver} {{ global: {' '.join(n + ';' for n in names)} }};\n")
        unversioned = versions.get(None, [])
        f.write(f"{{ global: {' '.join(n + ';' for n in unversioned)} local: *; }};\n"
                if not [v for v in versions if v] else "")
    cmd = ["gcc", "-shared", "-fPIC", "-O0", "-o", os.path.join(libdir, soname), src, f"-Wl,-soname,{soname}"]
    if any(v for v in versions):
        cmd.append(f"-Wl,--version-script={script}")
    subprocess.run(cmd, check=True)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = os.path.abspath(sys.argv[1])
    programs = sys.argv[2:] or ["build/candela", "build/tests/candela_tests"]
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.join(tmp, "candela-bundle")
        for d in ("bin", "lib", "fallback", "stubsrc"):
            os.makedirs(os.path.join(root, d))
        paths, keep, stubs, fallback = {}, {}, {}, {}
        todo = []
        for p in programs:
            shutil.copy2(p, os.path.join(root, "bin"))
            paths.update(ldd_paths(p))
            todo += [(n, p) for n in needed(p)]
        while todo:
            name, _ = todo.pop()
            if name in keep or name in stubs or name in fallback or SYSTEM.match(name):
                continue
            if FALLBACK.match(name):
                fallback[name] = paths[name]
            elif STUB.match(name):
                stubs[name] = paths[name]
            else:
                keep[name] = paths[name]
                todo += [(n, name) for n in needed(paths[name])]
        for name, path in keep.items():
            shutil.copy2(os.path.realpath(path), os.path.join(root, "lib", name))
        for name, path in fallback.items():
            shutil.copy2(os.path.realpath(path), os.path.join(root, "fallback", name))
        # The symbols the kept libraries and the programs import, and what they define themselves
        imported, provided = set(), set()
        for path in list(keep.values()) + programs:
            imported |= {base_name(s) for s in dyn_symbols(path, False)}
            provided |= {base_name(s) for s in dyn_symbols(path, True)}
        for name, path in stubs.items():
            make_stub(name, path, imported - provided, os.path.join(root, "stubsrc"), os.path.join(root, "lib"))
        shutil.rmtree(os.path.join(root, "stubsrc"))
        with open(os.path.join(root, "run"), "w") as f:
            f.write('#!/bin/sh\n# run PROGRAM ARGS...: a program of bin/ with the bundled libraries\n'
                    'here=$(cd "$(dirname "$0")" && pwd)\n'
                    'lp="$here/lib"\n'
                    '# this machine\'s libstdc++ when the target\'s is older (or missing)\n'
                    'if ! LD_LIBRARY_PATH="$lp" "$here/bin/candela" --version >/dev/null 2>&1; then lp="$lp:$here/fallback"; fi\n'
                    'p="$1"; shift\n'
                    'LD_LIBRARY_PATH="$lp${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" exec "$here/bin/$p" "$@"\n')
        os.chmod(os.path.join(root, "run"), 0o755)
        subprocess.run(["tar", "-C", tmp, "-cJf", out, "candela-bundle"], check=True,
                       env=dict(os.environ, XZ_OPT="-9 -T2"))
    print(f"{out}: {os.path.getsize(out) / 1e6:.1f} MB, {len(keep)} libraries, {len(stubs)} stubs: "
          + " ".join(sorted(stubs)))


if __name__ == "__main__":
    main()
