#!/usr/bin/env python3
"""Checks of README.md and docs/**/*.md: every relative link resolves (files and #anchors, as
GitHub renders headings); the docs speak of the product, not of its history: no issue
numbers, session talk, commit hashes or dated diary lines in prose (code blocks, inline code
and the generated tables between `<!-- results:begin -->` and `<!-- results:end -->` may name
a date and a commit; generated pages under docs/figures/ are checked for links only); and the
performance targets' table is what docs/results.py generates from docs/figures/results.json.
Usage: docs_test.py REPO_ROOT
"""
import glob
import os
import re
import subprocess
import sys

NARRATIVE = re.compile(r'\b(issue|issues) #?\d+\b|\bthis session\b|\bsession\'s\b', re.I)
# History in prose: a commit hash (7-40 hex digits with a digit and a letter), a date, a
# "tried on ..." or "(stop N)" note, a session, or a load average given with a measurement
HISTORY = [
    (re.compile(r'(?<![\w./#-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![\w-])'), 'commit hash'),
    (re.compile(r'\b20\d\d-[01]\d-[0-3]\d\b'), 'date'),
    (re.compile(r'\btried on\b', re.I), 'diary note'),
    (re.compile(r'\(stop \d+\)', re.I), 'diary note'),
    (re.compile(r'\bsessions?\b', re.I), 'session talk'),
    (re.compile(r'\bload average \d', re.I), 'dated measurement'),
]
GENERATED = re.compile(r'<!-- results:begin.*?-->.*?<!-- results:end -->', re.S)


def prose(raw):
    """raw with fenced code, inline code and generated tables blanked (line numbers kept)."""
    blank = lambda m: re.sub(r'[^\n]', ' ', m.group(0))
    text = re.sub(r'^```.*?^```', blank, raw, flags=re.S | re.M)
    text = GENERATED.sub(blank, text)
    return re.sub(r'`[^`\n]*`', blank, text)


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


def problems(files, read, generated=()):
    out = []
    for f in files:
        raw = read(f)
        for i, line in enumerate(raw.splitlines(), 1):
            if NARRATIVE.search(line):
                out.append(f'{f}:{i}: development narrative in the docs: "{NARRATIVE.search(line).group(0)}"')
        if f not in generated:
            for i, line in enumerate(prose(raw).splitlines(), 1):
                for pattern, what in HISTORY:
                    m = pattern.search(line)
                    if m:
                        out.append(f'{f}:{i}: {what} in prose (history belongs to git): "{m.group(0)}"')
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


DOCS_LINES, README_LINES, PERFORMANCE_LINES = 3500, 250, 300


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), '..', '..')
    files = [os.path.join(root, 'README.md')] + sorted(glob.glob(os.path.join(root, 'docs', '**', '*.md'), recursive=True))
    if len(files) < 5:
        print(f'docs_test: only {len(files)} documents under {root}: wrong root?')
        return 1

    def read(p):
        with open(p, encoding='utf-8') as fh:
            return fh.read()

    # The check must be able to fail: planted faults are found, and what is allowed passes
    planted = {
        '/p/a.md': '# Top\nsee [b](b.md#nowhere), [c](missing.md) and issue 12\n'
                   'measured at commit 5417b8a in a session\nTried on 2026-12-05, at load average 1.2 (stop 47)\n'
                   'the 1,007,620 triangles, `git show 5417b8a`, a defaced facade, 0x7f800000\n'
                   '```\nbuild 2026-12-05 4e91409\n```\n'
                   '<!-- results:begin -->\n| x | 2026-12-06, 5417b8a |\n<!-- results:end -->\n',
        '/p/b.md': '# Here\n',
        '/p/figures/c.md': 'generated 2026-12-03 at 6af7a133ae42\n'}
    found = problems(sorted(planted), lambda p: planted[p], generated={'/p/figures/c.md'})
    if len(found) != 9:
        print('docs_test: the planted faults were not found as expected; the check is broken:')
        print('\n'.join(found))
        return 1
    generated = {f for f in files if os.path.relpath(f, root).startswith(os.path.join('docs', 'figures') + os.sep)}
    found = problems(files, read, generated)
    results = os.path.join(root, 'docs', 'results.py')
    if os.path.exists(results):
        check = subprocess.run([sys.executable, results, '--check', os.path.join(root, 'docs', 'performance.md'),
                                os.path.join(root, 'docs', 'figures', 'results.json')],
                               capture_output=True, text=True)
        if check.returncode != 0:
            found.append('docs/performance.md: ' + (check.stdout + check.stderr).strip())
    # Sizes: the docs say what a reader needs, once (docs/**/*.md together, README and the
    # performance page each within its budget)
    def lines(p):
        return read(p).count('\n')
    docs = [f for f in files if not f.endswith('README.md')]
    for what, n, limit in (('docs/**/*.md together', sum(lines(f) for f in docs), DOCS_LINES),
                           ('README.md', lines(files[0]), README_LINES),
                           ('docs/performance.md', lines(os.path.join(root, 'docs', 'performance.md')),
                            PERFORMANCE_LINES)):
        if n > limit:
            found.append(f'{what}: {n} lines, over the budget of {limit}')
    for p in found:
        print(os.path.relpath(p, root) if p.startswith(root) else p)
    print(f'docs_test: {len(files)} documents, {len(found)} problem(s)')
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
