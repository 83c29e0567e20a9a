#!/usr/bin/env python3
"""No host or kernel source file is over 700 lines (docs/extending.md): a file that grows past
it is split along the list it serves (one file per light family, per glTF component, ...).
Usage: source_sizes_test.py REPO_ROOT
"""
import glob
import os
import sys

LIMIT = 700
PATTERNS = ('host/**/*.cpp', 'host/**/*.hpp', 'cl/**/*.cl', 'cl/**/*.h')


def oversized(root, limit=LIMIT):
    """(path, lines) of every source under root over limit lines."""
    found = []
    for pattern in PATTERNS:
        for path in sorted(glob.glob(os.path.join(root, pattern), recursive=True)):
            with open(path, encoding='utf-8') as f:
                n = sum(1 for _ in f)
            if n > limit:
                found.append((os.path.relpath(path, root), n))
    return found


def self_test():
    """The check itself finds a file over the limit and passes one at it."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, 'host', 'x'))
        os.makedirs(os.path.join(d, 'cl', 'y'))
        with open(os.path.join(d, 'host', 'x', 'big.cpp'), 'w') as f:
            f.write('\n' * (LIMIT + 1))
        with open(os.path.join(d, 'cl', 'y', 'ok.cl'), 'w') as f:
            f.write('\n' * LIMIT)
        assert oversized(d) == [('host/x/big.cpp', LIMIT + 1)], oversized(d)


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
    self_test()
    found = oversized(root)
    for path, n in found:
        print('%s: %d lines, over the limit of %d: split it' % (path, n, LIMIT))
    print('source_sizes: %d file(s) over %d lines' % (len(found), LIMIT))
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
