#!/usr/bin/env python3
"""Keeps the table of render settings (host/app/settings.cpp) in step with what uses it:
docs/cli.md's generated tables, `candela render --help`, the metadata and statistics of a
real render, `candela merge`'s checks and the kernel arguments the table names.

Usage: settings_test.py CANDELA REPO_ROOT [--update]
--update rewrites docs/cli.md's generated tables from `candela help-options --markdown`.
"""
import json
import os
import re
import sys
import tempfile

from candela_test_util import check, exr_metadata, finish, run

# ---- docs/cli.md: the generated tables ----

BLOCK = re.compile(r'(<!-- generated from host/app/settings\.cpp by `candela help-options --markdown (\w+)`;[^\n]*-->\n)'
                   r'(.*?)(<!-- end of the generated table -->)', re.S)


def check_docs(candela, root, update):
    path = os.path.join(root, 'docs', 'cli.md')
    text = open(path, encoding='utf-8').read()
    names = [m.group(2) for m in BLOCK.finditer(text)]
    check(sorted(names) == ['options', 'record'], f'docs/cli.md has the generated tables options and record ({names})')

    def generated(m):
        return run([candela, 'help-options', '--markdown', m.group(2)], check=True).stdout

    if update:
        text = BLOCK.sub(lambda m: m.group(1) + generated(m) + m.group(4), text)
        open(path, 'w', encoding='utf-8').write(text)
        print(f'rewrote the generated tables of {path}')
        return
    for m in BLOCK.finditer(text):
        want = generated(m)
        same = m.group(3) == want
        check(same, f'docs/cli.md table "{m.group(2)}" equals `candela help-options --markdown {m.group(2)}`')
        if not same:
            print('  docs/cli.md differs from the settings table; rewrite it with:\n'
                  f'  python3 tests/app/settings_test.py {candela} {root} --update')


def section(text, heading):
    start = text.index(heading)
    end = text.find('\n#', start + len(heading))
    return text[start:end if end >= 0 else len(text)]


def check_docs_keys(root, listing):
    """The keys of the record that are not settings, each named in the docs' tables."""
    text = open(os.path.join(root, 'docs', 'cli.md'), encoding='utf-8').read()
    outputs, stats = section(text, '### Outputs'), section(text, '### Statistics')
    for k in listing['results']:
        if k['metadata']:
            check(f'`candela:{k["key"]}`' in outputs, f'docs/cli.md, Outputs: names candela:{k["key"]}')
        if k['stats']:
            check(f'`{k["key"]}`' in stats, f'docs/cli.md, Statistics: names {k["key"]}')


# ---- --help ----

def check_help(candela, listing):
    text = run([candela, 'render', '--help'], check=True).stdout
    in_help = set(re.findall(r'^\s+(?:-\w,)?(--[\w-]+)', text, re.M))
    table = {o['flags'].split(',')[-1] for o in listing['options'] if o['flags'].startswith('-')} | {'--help'}
    check(in_help == table, f'every flag of `render --help` is in the table and back (only in --help: '
          f'{sorted(in_help - table)}, only in the table: {sorted(table - in_help)})')
    positional = [o['flags'] for o in listing['options'] if not o['flags'].startswith('-')]
    check(all(re.search(rf'^\s+{p}\b', text, re.M) for p in positional), f'--help lists the positional {positional}')
    flat = ' '.join(text.split())
    for o in listing['options']:
        check(' '.join(o['help'].split()) in flat, f'--help gives the table\'s help of {o["flags"]}')
        if o['default']:
            check(o['default'] in o['help'] or o['default'] in o['doc'],
                  f'the help or docs of {o["flags"]} state its default {o["default"]}')


# ---- the kernel hooks the table names ----

def check_kernel(root, listing):
    renderer = open(os.path.join(root, 'host', 'render', 'renderer.cpp'), encoding='utf-8').read()
    header = open(os.path.join(root, 'host', 'render', 'renderer.hpp'), encoding='utf-8').read()
    kernel_settings = re.findall(r'X\(\s*\w+,\s*(\w+),', header[header.index('#define CD_KERNEL_SETTINGS'):
                                                            header.index('struct RenderSettings')])
    types = open(os.path.join(root, 'cl', 'shared', 'device_types.h'), encoding='utf-8').read()
    sources = ''
    for base in ('host', 'cl'):
        for d, _, files in os.walk(os.path.join(root, base)):
            for f in files:
                if f.endswith(('.cpp', '.hpp', '.h', '.cl')):
                    sources += open(os.path.join(d, f), encoding='utf-8').read()
    params = types[types.rindex('typedef struct', 0, types.index('} RenderParams;')):types.index('} RenderParams;')]
    for o in listing['options']:
        k = o['kernel']
        if not k:
            continue
        if k.startswith('RenderParams.'):
            field = k.split('.', 1)[1]
            check(re.search(rf'\b{field};', params) is not None and
                  (f'params_host_.{field} =' in renderer or field in kernel_settings),
                  f'{o["flags"]} reaches RenderParams.{field} (device_types.h; set in renderer.cpp, or by '
                  'CD_KERNEL_SETTINGS)')
        else:
            pattern = re.escape(k).replace(r'\*', r'\w+')
            check(re.search(pattern, sources) is not None, f'{o["flags"]} reaches the build option {k}')


# ---- a real render: its metadata and statistics ----

def render(candela, scene, tmp, name, *options):
    out = os.path.join(tmp, name)
    r = run([candela, 'render', scene, '-o', out + '.exr', '--stats', out + '.json', '--width', '8', '--height', '8',
             '--spp', '1', '--device', os.environ.get('CANDELA_TEST_DEVICE', 'pocl'), '-q', *options])
    if r.returncode != 0:
        print(r.stdout + r.stderr)
    return out if r.returncode == 0 else None


def text_of(value):
    if isinstance(value, bool):
        return 'on' if value else 'off'
    return str(value)


def check_record(candela, scene, tmp, listing):
    options = ['--seed', '5', '--max-depth', '7', '--filter', 'gaussian', '--no-energy-compensation', '--generic',
               '--sample-offset', '3', '--strategy', 'nee']
    out = render(candela, scene, tmp, 'record', *options)
    check(out is not None, 'a render with --stats')
    if out is None:
        return
    meta = exr_metadata(out + '.exr', text=True)
    stats = json.load(open(out + '.json'))
    settings = [o for o in listing['options'] if o['recorded']]
    want_stats = {o['stats'] for o in settings if o['stats']} | {k['key'] for k in listing['results'] if k['stats']}
    check(set(stats) == want_stats, f'the stats JSON holds exactly the table\'s keys (only in the JSON: '
          f'{sorted(set(stats) - want_stats)}, only in the table: {sorted(want_stats - set(stats))})')
    if meta is None:
        print('skip  the EXR metadata (neither the OpenImageIO module nor oiiotool)')
        return
    want_meta = {o['metadata'] for o in settings if o['metadata']} | {
        k['key'] for k in listing['results'] if k['metadata'] and k['always']}
    optional = {k['key'] for k in listing['results'] if k['metadata'] and not k['always']}
    extra = set(meta) - want_meta - optional - {'tonemap'}  # tonemap: PNG outputs only
    check(want_meta <= set(meta) and not extra, f'the EXR metadata holds the table\'s keys (missing: '
          f'{sorted(want_meta - set(meta))}, not in the table: {sorted(extra)})')
    for o in settings:
        if o['metadata'] and o['stats'] and o['metadata'] in meta and o['stats'] in stats:
            check(meta[o['metadata']] == text_of(stats[o['stats']]),
                  f'{o["flags"]}: candela:{o["metadata"]} {meta[o["metadata"]]} is stats {o["stats"]} '
                  f'{stats[o["stats"]]}')
    given = {'seed': '5', 'max_depth': '7', 'filter': 'gaussian', 'energy_compensation': 'off', 'sample_offset': '3',
             'strategy': 'nee'}
    for key, value in given.items():
        check(meta.get(key) == value, f'the option given reaches the metadata: candela:{key} {meta.get(key)}')
    check(stats.get('generic_kernel') is True, '--generic reaches the stats: generic_kernel')


# ---- merge: each setting that must match, changed in one shard, is refused ----

def other_value(option):
    """A value of the option that differs from its default, or None."""
    if not option['flags'].startswith('-'):
        return None
    flag = option['flags'].split(',')[-1]
    if not option['value_name']:
        return [flag]
    choices = option['value_name'].split('|')
    if len(choices) > 1:
        return [flag, next(c for c in choices if c != option['default'])]
    if option['default'].isdigit():
        return [flag, str(int(option['default']) + 1)]
    return None


def check_merge(candela, scene, tmp, listing):
    must = [o for o in listing['options'] if o['must_match']]
    keys = [o['metadata'] for o in must] + [k['key'] for k in listing['results'] if k['must_match']]
    check(listing['must_match'] == keys, f'merge requires exactly the table\'s must-match keys {keys}')
    first = render(candela, scene, tmp, 'm0')
    same = render(candela, scene, tmp, 'm1', '--sample-offset', '1')
    r = run([candela, 'merge', first + '.exr', same + '.exr', '-o', os.path.join(tmp, 'm01.exr')])
    check(r.returncode == 0, 'merge takes two shards of the same settings')
    for o in must:
        change = other_value(o)
        if change is None:
            print(f'skip  merge with a different {o["flags"]} (no other value known)')
            continue
        shard = render(candela, scene, tmp, 'mx-' + o['metadata'], '--sample-offset', '1', *change)
        r = run([candela, 'merge', first + '.exr', shard + '.exr', '-o', os.path.join(tmp, 'mx.exr')])
        check(r.returncode == 1 and f'different {o["metadata"]}' in r.stderr,
              f'merge refuses shards with different {o["flags"]} ({" ".join(change)}): {r.stderr.strip()}')


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    candela, root = os.path.abspath(sys.argv[1]), sys.argv[2]
    update = '--update' in sys.argv[3:]
    check_docs(candela, root, update)
    if update:
        return
    listing = json.loads(run([candela, 'help-options', '--json'], check=True).stdout)
    check_docs_keys(root, listing)
    check_help(candela, listing)
    check_kernel(root, listing)
    scene = os.path.join(root, 'scenes', 'cornell-box', 'cornell-box.gltf')
    with tempfile.TemporaryDirectory() as tmp:
        check_record(candela, scene, tmp, listing)
        check_merge(candela, scene, tmp, listing)
    finish()
    print('all passed')


if __name__ == '__main__':
    main()
