#!/usr/bin/env python3
"""Static checks of the OpenCL C sources that compilers do not make (README, Kernel portability).

Fails when a function assigns to, increments, or takes the address of a struct parameter
passed by value: Mesa's rusticl passes such parameters by reference, so the caller would
see the change. Usage: kernel_lint_test.py REPO_ROOT
"""
import glob
import os
import re
import sys

VECTOR_TYPES = re.compile(r'^(float|int|uint|char|uchar|short|ushort|long|ulong|half|double)\d*$')


def struct_types(sources):
    """Names introduced by `typedef struct {...} Name;` in the sources."""
    names = set()
    for text in sources.values():
        names.update(re.findall(r'typedef\s+struct\s*\w*\s*\{[^}]*\}\s*(\w+)\s*;', text, re.S))
    return names


def functions(text):
    """(name, parameter list, body) of each function definition."""
    text = re.sub(r'//[^\n]*', '', text)
    text = re.sub(r'/\*.*?\*/', '', text, flags=re.S)
    for m in re.finditer(r'^[A-Za-z_][\w \t\*]*?\b(\w+)\s*\(([^;{}()]*)\)\s*\{', text, re.M):
        depth, i = 1, m.end()
        while depth and i < len(text):
            depth += text[i] == '{'
            depth -= text[i] == '}'
            i += 1
        yield m.group(1), m.group(2), text[m.end():i]


def violations(sources):
    structs = struct_types(sources)
    found = []
    for path, text in sources.items():
        for name, params, body in functions(text):
            for p in params.split(','):
                pm = re.match(r'\s*(?:const\s+)?(\w+)\s+(\w+)\s*$', p)
                if not pm or pm.group(1) not in structs or VECTOR_TYPES.match(pm.group(1)):
                    continue
                var = re.escape(pm.group(2))
                member = r'(?:\.\w+|\[[^\]]*\])*'
                writes = [
                    r'(?<![\w.>])' + var + member + r'\s*(?:[-+*/%&|^]|<<|>>)?=(?!=)',  # assignment
                    r'(?<![\w.>])' + var + member + r'\s*(?:\+\+|--)',  # post-increment
                    r'(?:\+\+|--)\s*' + var + r'\b',  # pre-increment
                    r'&\s*' + var + r'\b(?!\s*&)',  # address taken (the callee may write)
                ]
                for w in writes:
                    hit = re.search(w, body)
                    if hit:
                        found.append(f'{path}: {name}() changes its by-value parameter {pm.group(1)} '
                                     f'{pm.group(2)} ("{hit.group(0).strip()}"); copy it into a local first')
                        break
    return found


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
    # Every kernel file, found recursively: the renderer's cl/ and the test kernels beside their tests
    paths = sorted(glob.glob(os.path.join(root, 'cl', '**', '*.cl'), recursive=True) +
                   glob.glob(os.path.join(root, 'cl', '**', '*.h'), recursive=True) +
                   glob.glob(os.path.join(root, 'tests', '**', '*.cl'), recursive=True))
    sources = {os.path.relpath(p, root): open(p, encoding='utf-8').read() for p in paths}
    # The files checked are exactly the program's (cl/program.cmake) and the test kernels: a
    # kernel file moved or added where this check does not look fails here
    with open(os.path.join(root, 'cl', 'program.cmake'), encoding='utf-8') as f:
        program = set(re.findall(r'^\s*(cl/[^\s)]+)', f.read(), re.M))
    found = {p for p in sources if p.startswith('cl' + os.sep)}
    if not program or program != found:
        print(f'kernel_lint: cl/program.cmake lists {sorted(program - found)} not found, '
              f'and the files {sorted(found - program)} are not in the program')
        return 1
    if not any(p.startswith('tests' + os.sep) for p in sources):
        print(f'kernel_lint: no test kernels under {root}/tests: wrong root?')
        return 1
    # The check must be able to fail: a planted violation is found
    planted = {'planted.cl': 'typedef struct { float a; } P;\nvoid f(P p) { p.a = 1.0f; }\n'}
    if not violations(planted):
        print('kernel_lint: the planted violation was not found; the check is broken')
        return 1
    found = violations(sources)
    for v in found:
        print(v)
    print(f'kernel_lint: {len(sources)} files, {len(found)} violation(s)')
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
