#!/usr/bin/env python3
"""The host's layers hold (docs/architecture.md, Layers): each folder of host/ includes only
the folders below it. The render layer sees the compiled scene (compile/compiled_scene.hpp,
which includes nothing of the scene description), never the scene description itself.
Usage: layers_test.py REPO_ROOT
"""
import glob
import os
import re
import sys

# folder -> the folders (or single headers) its files may include
ALLOWED = {
    'base': {'base', 'cl'},
    'scene': {'base', 'cl', 'scene'},
    'gltf': {'base', 'cl', 'scene', 'gltf'},
    'compile': {'base', 'cl', 'scene', 'compile'},
    'device': {'base', 'cl', 'device'},
    'render': {'base', 'cl', 'device', 'render', 'compile/compiled_scene.hpp'},
    'app': {'base', 'cl', 'scene', 'gltf', 'compile', 'device', 'render', 'app'},
}


def violations(files):
    """(file, included) pairs that break ALLOWED; files maps 'host/F/x.cpp' -> text."""
    found = []
    for path, text in files.items():
        folder = path.split('/')[1]
        allowed = ALLOWED.get(folder)
        if allowed is None:
            found.append((path, 'a folder the layer list does not name'))
            continue
        for inc in re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M):
            if inc.split('/')[0] not in allowed and inc not in allowed:
                found.append((path, inc))
    return found


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
    paths = sorted(glob.glob(os.path.join(root, 'host', '*', '*.[ch]pp')))
    files = {os.path.relpath(p, root).replace(os.sep, '/'): open(p, encoding='utf-8').read() for p in paths}
    if len(files) < 20:
        print(f'layers_test: only {len(files)} host files under {root}: wrong root?')
        return 1
    planted = {'host/render/x.cpp': '#include "scene/scene.hpp"\n', 'host/base/y.hpp': '#include "base/error.hpp"\n'}
    if violations(planted) != [('host/render/x.cpp', 'scene/scene.hpp')]:
        print('layers_test: the planted violation was not found; the check is broken')
        return 1
    found = violations(files)
    for path, inc in found:
        print(f'{path} includes "{inc}", which its layer may not (docs/architecture.md, Layers)')
    print(f'layers_test: {len(files)} files, {len(found)} violation(s)')
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
