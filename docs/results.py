#!/usr/bin/env python3
"""The performance targets' table, generated from docs/figures/results.json.

The JSON holds one current figure per target:
  {"targets": [{"key", "target", "figure", "command", "host", "date", "commit"}, ...]}
The benchmark scripts replace a target's entry when they measure it again, so a new
figure replaces the old one instead of stacking beside it.

  python3 docs/results.py          rewrite the tables of docs/performance.md
  python3 docs/results.py --check  exit 1 if a table differs from what the JSON gives

Each table lies between `<!-- results:begin -->` and `<!-- results:end -->`; a begin
marker may name the keys it shows, `<!-- results:begin keys=a,b -->`, else it shows all.
"""
import json
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, 'figures', 'results.json')
DOC = os.path.join(HERE, 'performance.md')
FIELDS = ('key', 'target', 'figure', 'command', 'host', 'date', 'commit')
BLOCK = re.compile(r'(<!-- results:begin(?: keys=([\w,.-]+))? -->\n)(.*?)(<!-- results:end -->)', re.S)


def load(path=RESULTS):
    with open(path, encoding='utf-8') as fh:
        data = json.load(fh)
    keys = set()
    for t in data['targets']:
        missing = [f for f in FIELDS if not str(t.get(f, '')).strip()]
        if missing:
            raise ValueError(f'{path}: target {t.get("key", "?")} lacks {", ".join(missing)}')
        if t['key'] in keys:
            raise ValueError(f'{path}: target {t["key"]} appears twice')
        keys.add(t['key'])
    return data


def cell(text):
    return str(text).replace('|', '\\|').replace('\n', ' ')


def table(targets):
    rows = ['| target | figure | command | measured |', '|---|---|---|---|']
    for t in targets:
        rows.append('| %s | %s | `%s` | %s, %s; %s |' % (
            cell(t['target']), cell(t['figure']), cell(t['command']), t['date'], t['commit'], cell(t['host'])))
    return '\n'.join(rows) + '\n'


def render(doc, data):
    """The document with every results block rewritten from data."""
    by_key = {t['key']: t for t in data['targets']}

    def block(m):
        if m.group(2):
            unknown = [k for k in m.group(2).split(',') if k not in by_key]
            if unknown:
                raise ValueError('results block names unknown keys: ' + ', '.join(unknown))
            targets = [by_key[k] for k in m.group(2).split(',')]
        else:
            targets = data['targets']
        return m.group(1) + table(targets) + m.group(4)

    out, n = BLOCK.subn(block, doc)
    if n == 0:
        raise ValueError('no <!-- results:begin --> ... <!-- results:end --> block')
    return out


def record(key, path=RESULTS, **fields):
    """Sets the fields of target `key` (adding it at the end if new) in the results file."""
    data = load(path) if os.path.exists(path) else {'targets': []}
    entry = next((t for t in data['targets'] if t['key'] == key), None)
    if entry is None:
        entry = {'key': key}
        data['targets'].append(entry)
    entry.update(fields)
    with open(path, 'w', encoding='utf-8') as fh:
        fh.write('{"targets": [\n')
        fh.write(',\n'.join('  ' + json.dumps({f: t.get(f, '') for f in FIELDS}, ensure_ascii=False)
                            for t in data['targets']))
        fh.write('\n]}\n')


def main(argv):
    check = '--check' in argv
    args = [a for a in argv if a != '--check']
    doc_path = args[0] if args else DOC
    results_path = args[1] if len(args) > 1 else RESULTS
    try:
        data = load(results_path)
        with open(doc_path, encoding='utf-8') as fh:
            doc = fh.read()
        new = render(doc, data)
    except (OSError, ValueError) as e:
        print(f'results.py: {e}')
        return 1
    if check:
        if new != doc:
            print(f'results.py: the table in {doc_path} differs from {results_path}; run python3 docs/results.py')
            return 1
        return 0
    if new != doc:
        with open(doc_path, 'w', encoding='utf-8') as fh:
            fh.write(new)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
