#!/usr/bin/env python3
"""Checks of README.md and docs/*.md: every relative link resolves (files and #anchors, as
GitHub renders headings), and the docs speak of the product (no issue numbers or session
talk). Usage: docs_test.py REPO_ROOT
"""
import glob
import os
import re
import sys

NARRATIVE = re.compile(r'\b(issue|issues) #?\d+\b|\bthis session\b|\bsession\'s\b', re.I)


def slug(heading):
    s = re.sub(r'[^\w\- ]', '', heading.strip().lower())
    return s.replace(' ', '-')


def anchors(text):
    found, seen, in_code = set(), {}, False
    for line in text.splitlines():
        if line.startswith('```'):
            in_code = not in_code
            continue
        m = re.match(r'^#{1,6}\s+(.*)', line)
        if m and not in_code:
            s = slug(m.group(1))
            n = seen.get(s, 0)
            seen[s] = n + 1
            found.add(s if n == 0 else f'{s}-{n}')
    return found


def problems(files, read):
    out = []
    for f in files:
        raw = read(f)
        for i, line in enumerate(raw.splitlines(), 1):
            if NARRATIVE.search(line):
                out.append(f'{f}:{i}: development narrative in the docs: "{NARRATIVE.search(line).group(0)}"')
        text = re.sub(r'```.*?```', '', raw, flags=re.S)
        text = re.sub(r'`[^`\n]*`', '', text)
        for m in re.finditer(r'\]\(([^)\s]+)\)', text):
            target = m.group(1)
            if re.match(r'^[a-z]+:', target):
                continue
            path, _, frag = target.partition('#')
            dest = os.path.normpath(os.path.join(os.path.dirname(f), path)) if path else f
            if not os.path.exists(dest) and dest not in files:
                out.append(f'{f}: broken link {target}')
            elif frag and dest.endswith('.md') and frag not in anchors(read(dest)):
                out.append(f'{f}: no heading for {target}')
    return out


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
    files = [os.path.join(root, 'README.md')] + sorted(glob.glob(os.path.join(root, 'docs', '**', '*.md'), recursive=True))
    if len(files) < 5:
        print(f'docs_test: only {len(files)} documents under {root}: wrong root?')
        return 1

    def read(p):
        with open(p, encoding='utf-8') as fh:
            return fh.read()

    # The check must be able to fail: planted faults are found
    planted = {'/p/a.md': '# Top\nsee [b](b.md#nowhere), [c](missing.md) and issue 12\n', '/p/b.md': '# Here\n'}
    if len(problems(['/p/a.md', '/p/b.md'], lambda p: planted[p])) != 3:
        print('docs_test: the planted faults were not all found; the check is broken')
        return 1
    found = problems(files, read)
    for p in found:
        print(os.path.relpath(p, root) if p.startswith(root) else p)
    print(f'docs_test: {len(files)} documents, {len(found)} problem(s)')
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
