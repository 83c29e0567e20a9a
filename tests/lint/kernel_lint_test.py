#!/usr/bin/env python3
"""Static checks of the OpenCL C sources that compilers do not make (README, Kernel portability).

Fails when a function assigns to, increments, or takes the address of a struct parameter
passed by value: Mesa's rusticl passes such parameters by reference, so the caller would
see the change. Fails when the extension lists of cl/shared/device_types.h and the code
disagree (docs/extending.md): the MATERIAL_* and LIGHT_* ids defined above CD_MATERIALS and
CD_LIGHTS are exactly their entries, numbered 0, 1, ...; no kernel code compares a type with
an id or switches on it (the dispatch is generated from the lists); every type has its
functions with the one signature, and the generated dispatch calls each of them; every
CD_FEATURE_* macro the kernels use is in CD_SCENE_FEATURES, whose defaults come from the
list alone. Fails when the glTF mixture's lists (cl/bsdf/gltf/mixture.cl) and its files
disagree: every GLTF_COMPONENTS entry has its file cl/bsdf/gltf/NAME.cl defining its params,
at_wo, flags, weight, sample, lobes and eval functions, GLTF_EVAL_ORDER holds each entry once, bsdf_gltf.cl sums
the terms through it, and cl/bsdf/gltf/ holds no other file than the shared ones. Fails when
a union in kernel code (outside cl/shared/device_types.h, whose structs hold only 4-byte
scalars) does not begin with a float4 or uint4 array that spans it (a union only measured by
sizeof, never an object, excepted): a compiler may copy a union as the member it lays it out
by and drop that member's padding (NVIDIA's OpenCL compiler lost a conductor's k.z under a
bool's padding). Usage: kernel_lint_test.py REPO_ROOT
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


def measured_unions(sources):
    """Spans (path, start, end) of `typedef union {...} Name;` whose Name the sources use only
    in sizeof(Name): never an object, so never copied."""
    code = {p: re.sub(r'//[^\n]*', '', t) for p, t in sources.items()}
    spans = []
    for path, text in code.items():
        for m in re.finditer(r'\btypedef\s+union\s*\w*\s*\{[^}]*\}\s*(\w+)\s*;', text):
            name = re.escape(m.group(1))
            uses = sum(len(re.findall(r'\b' + name + r'\b', t)) for t in code.values()) - 1
            measured = sum(len(re.findall(r'\bsizeof\s*\(\s*' + name + r'\s*\)', t)) for t in code.values())
            if uses == measured:
                spans.append((path, m.start(), m.end()))
    return spans


def union_violations(sources):
    """Unions whose first member is not a padding-free array of 4-wide vectors, but for those
    only measured (measured_unions)."""
    found = []
    measured = measured_unions(sources)
    for path, text in sources.items():
        if path.endswith(os.path.join('shared', 'device_types.h')):
            continue
        text = re.sub(r'//[^\n]*', '', text)
        for m in re.finditer(r'\bunion\s*\w*\s*\{\s*([^;]*;)', text):
            if any(p == path and a <= m.start() < b for p, a, b in measured):
                continue
            if not re.match(r'(?:float|uint|int)4\s+\w+\s*\[[^\]]+\]\s*;', m.group(1)):
                found.append(f'{path}: a union begins with "{m.group(1).strip()}", not a float4 array spanning it '
                             f'(a copy may drop the padding of the member it is laid out by)')
    return found


def strip_comments(text):
    text = re.sub(r'//[^\n]*', '', text)
    return re.sub(r'/\*.*?\*/', '', text, flags=re.S)


def macro_body(text, name):
    """The body of `#define name(...)` with its continuation lines, or None."""
    m = re.search(r'^#define ' + name + r'\([^)]*\)((?:[^\n]*\\\n)*[^\n]*)', text, re.M)
    return m.group(1).replace('\\\n', ' ') if m else None


def list_entries(body):
    """The argument lists of the X(...) entries of a list macro's body (strings may hold commas
    and parentheses)."""
    entries, i = [], 0
    while True:
        i = body.find('X(', i)
        if i < 0:
            return entries
        i += 2
        args, arg, depth, quote = [], '', 1, False
        while depth:
            c = body[i]
            if quote:
                quote = c != '"' or body[i - 1] == '\\'
            elif c == '"':
                quote = True
            elif c == '(':
                depth += 1
            elif c == ')':
                depth -= 1
            elif c == ',' and depth == 1:
                args.append(arg.strip())
                arg = ''
                i += 1
                continue
            if depth:
                arg += c
            i += 1
        args.append(arg.strip())
        entries.append(args)


def defines_above(text, name):
    """(macro, value) of the run of `#define MACRO <n>u` lines right above `#define name(X)`."""
    lines = text[:text.find('#define ' + name + '(')].rstrip('\n').split('\n')
    while lines and lines[-1].lstrip().startswith('//'):  # comments between (clang-format off)
        lines.pop()
    run = []
    while lines and re.match(r'#define \w+ \d+u\b', lines[-1]):
        m = re.match(r'#define (\w+) (\d+)u\b', lines.pop())
        run.insert(0, (m.group(1), int(m.group(2))))
    return run


def normalize_type(param):
    """The type of a parameter declaration without its name: 'const Bsdf* b' -> 'const Bsdf*'."""
    param = re.sub(r'\s+', ' ', param.strip())
    m = re.match(r'^(.*?[\s\*])(\w+)$', param)
    t = m.group(1) if m else param
    return re.sub(r'\s*\*', '*', t).strip()


def definitions(text):
    """name -> (return type, [parameter types]) of each function defined in text."""
    found = {}
    for m in re.finditer(r'^([A-Za-z_][\w \t\*]*?)\s*\b(\w+)\s*\(([^;{}()]*)\)\s*\{', text, re.M):
        params = [normalize_type(p) for p in m.group(3).split(',')] if m.group(3).strip() else []
        found[m.group(2)] = (re.sub(r'\s+', ' ', m.group(1).strip()), params)
    return found


# The one signature of each per-type function: suffix -> (return type, parameter types)
LOBE = {
    'params': ('void', ['const SceneData*', '__global const Material*', 'const SurfaceHit*', 'Bsdf*']),
    'flags': ('uint', ['const Bsdf*']),
    'eval': ('float3', ['const Bsdf*', 'float3', 'float3', 'float*']),
    'sample': ('bool', ['const Bsdf*', 'float3', 'float', 'float2', 'BsdfSample*', 'BsdfLobes*']),
    'lobes': ('void', ['const Bsdf*', 'float3', 'BsdfLobes*']),
}
COMPONENT = {
    'params': ('bool', ['const SceneData*', '__global const Material*', 'const SurfaceHit*', 'Bsdf*']),
    'at_wo': ('void', ['const Bsdf*', 'float3', 'GltfAtWo*']),
    'flags': ('uint', ['const Bsdf*']),
    'weight': ('float', ['const Bsdf*', 'const GltfAtWo*', 'float']),
    'sample': ('int', ['const Bsdf*', 'const GltfAtWo*', 'float3', 'float', 'float2', 'BsdfSample*']),
    'lobes': ('void', ['const Bsdf*', 'const GltfAtWo*', 'float3', 'float', 'BsdfLobes*']),
}
LIGHT = {
    'sample': ('bool', ['const SceneData*', '__global const Light*', 'const LightSampleContext*', 'float2',
                        'LightSample*']),
    'pdf': ('float', ['const SceneData*', '__global const Light*', 'const LightSampleContext*', 'float3']),
    'extent': ('void', ['const SceneData*', '__global const Light*', 'float3', 'LightExtent*']),
    'prim': ('uint', ['__global const Light*']),
}


def generated_callers(text, prefix, suffix):
    """Macros of text whose body calls prefix_##NAME##_suffix (a dispatch to generate from a list)."""
    callers = []
    for m in re.finditer(r'^#define (\w+)\([^)]*\)((?:[^\n]*\\\n)*[^\n]*)', text, re.M):
        if re.search(prefix + r'_##\w+##_' + suffix + r'\(', m.group(2)):
            callers.append(m.group(1))
    return callers


def list_violations(sources, features_path, lists):
    """Disagreements between the lists and the kernel code in sources (path -> text).
    features_path: the file of CD_SCENE_FEATURES. lists: list macro -> (file of the list,
    prefix, {suffix: signature} of each entry's functions, file of the dispatch, whether the
    third column is a feature)."""
    found = []
    features = list_entries(macro_body(sources[features_path], 'CD_SCENE_FEATURES') or '')
    feature_macros = {e[1] for e in features if len(e) == 4}
    if not features or len(feature_macros) != len(features):
        found.append(f'{features_path}: CD_SCENE_FEATURES is missing or not X(name, macro, default, needs)')
    code = {p: strip_comments(t) for p, t in sources.items()}
    for path, text in code.items():
        for m in re.finditer(r'#\s*(?:define|ifndef|undef)\s+(CD_FEATURE_\w+)', text):
            found.append(f'{path}: {m.group(0)}: the defaults of kernel features come from CD_SCENE_FEATURES alone')
        for name in sorted(set(re.findall(r'\bCD_FEATURE_\w+', text)) - feature_macros):
            found.append(f'{path}: {name} is not in CD_SCENE_FEATURES')
    defs = {}
    for text in code.values():
        defs.update(definitions(text))
    for macro, (list_path, prefix, functions, dispatch_path, has_feature) in lists.items():
        entries = list_entries(macro_body(sources.get(list_path, ''), macro) or '')
        if not entries or any(len(e) != 3 for e in entries):
            found.append(f'{list_path}: {macro} is missing or not X(id, name, {"feature" if has_feature else "kind"})')
            continue
        ids = [e[0] for e in entries]
        defined = defines_above(sources[list_path], macro)
        if [d[0] for d in defined] != ids or [d[1] for d in defined] != list(range(len(ids))):
            found.append(f'{list_path}: the ids defined above {macro} ({", ".join(f"{d[0]} {d[1]}" for d in defined)}) '
                         f'are not its entries ({", ".join(ids)}) numbered 0, 1, ...')
        for e in entries:
            if has_feature and e[2] != '1' and e[2] not in feature_macros:
                found.append(f'{list_path}: {macro} entry {e[1]}: feature {e[2]} is neither 1 nor in CD_SCENE_FEATURES')
        # Only the generated dispatch tells the types apart
        id_pattern = r'\b(?:' + '|'.join(re.escape(i) for i in ids) + r')\b'
        for path, text in code.items():
            for m in re.finditer(r'case\s+' + id_pattern + r'|[!=]=\s*' + id_pattern + '|' + id_pattern + r'\s*[!=]=',
                                 text):
                found.append(f'{path}: "{m.group(0)}": a hand-written test of the type; dispatch through {macro}')
        # Each entry's functions with the one signature, and a dispatch generated from the list calling each
        dispatch_text = code.get(dispatch_path, '')
        for suffix, signature in functions.items():
            for e in entries:
                fn = f'{prefix}_{e[1]}_{suffix}'
                if fn not in defs:
                    found.append(f'{macro} entry {e[1]}: no {fn}()')
                elif defs[fn] != signature:
                    found.append(f'{fn}: {defs[fn][0]} ({", ".join(defs[fn][1])}), not the one signature '
                                 f'{signature[0]} ({", ".join(signature[1])})')
            callers = generated_callers(dispatch_text, prefix, suffix)
            if not any(re.search(macro + r'\(\s*' + c + r'\s*\)', dispatch_text) for c in callers):
                found.append(f'{dispatch_path}: no dispatch of {prefix}_NAME_{suffix} generated from {macro}')
    return found


PLANTED_TYPES = """
#define CD_SCENE_FEATURES(X) X(a, CD_FEATURE_A, 1, "a (b, c)")
#define T_ONE 0u
#define T_TWO 1u
#define CD_TS(X) X(T_ONE, one, 1) X(T_TWO, two, CD_FEATURE_A)
"""
PLANTED_GOOD = """
uint t_one_get(const Bsdf* b) { return 1u; }
uint t_two_get(const Bsdf* b) { return 2u; }
#define T_GET(id, name, feature) \\
  if (feature && b->type == id) return t_##name##_get(b);
uint t_get(const Bsdf* b) { CD_TS(T_GET) return 0u; }
"""
PLANTED_DISPATCH = {'CD_TS': ('types.h', 't', {'get': ('uint', ['const Bsdf*'])}, 'good.cl', True)}


def planted_cases():
    """(what, sources that replace or join the clean ones) of each planted violation."""
    three = PLANTED_TYPES.replace('#define CD_TS', '#define T_THREE 2u\n#define CD_TS').replace(
        'X(T_TWO, two, CD_FEATURE_A)', 'X(T_TWO, two, CD_FEATURE_A) X(T_THREE, three, 1)')
    return [
        ('a switch on the type', {'bad.cl': 'uint f(uint t) { switch (t) { case T_TWO: return 1u; } return 0u; }'}),
        ('a comparison with an id', {'bad.cl': 'bool f(const Bsdf* b) { return b->type == T_ONE; }'}),
        ('an unknown feature', {'bad.cl': '#if CD_FEATURE_B\n#endif'}),
        ('a feature default outside the list', {'bad.cl': '#ifndef CD_FEATURE_A\n#define CD_FEATURE_A 1\n#endif'}),
        ('a type without its function', {'types.h': three}),
        ('a function of another signature', {'types.h': three, 'bad.cl': 'uint t_three_get(Bsdf* b) { return 3u; }'}),
        ('an id defined but not listed', {'types.h': PLANTED_TYPES.replace('#define T_TWO 1u', '#define T_TWO 1u\n#define T_NEW 2u')}),
        ('ids out of list order', {'types.h': PLANTED_TYPES.replace('T_ONE 0u', 'T_ONE 1u').replace('T_TWO 1u', 'T_TWO 0u')}),
        ('a dispatch not generated from the list', {'good.cl': PLANTED_GOOD.replace('CD_TS(T_GET)', '')}),
    ]


def planted_list_violations():
    """What the list check misses among the planted violations (empty when it finds each)."""
    base = {'types.h': PLANTED_TYPES, 'good.cl': PLANTED_GOOD}
    missed = ['the clean sources (it reports one there)'] if list_violations(base, 'types.h', PLANTED_DISPATCH) else []
    for what, sources in planted_cases():
        if not list_violations(dict(base, **sources), 'types.h', PLANTED_DISPATCH):
            missed.append(what)
    return missed


# The glTF mixture (cl/bsdf/gltf/mixture.cl): one file per component, cl/bsdf/gltf/NAME.cl,
# defining its functions; the files beside them that are no component
GLTF_DIR = os.path.join('cl', 'bsdf', 'gltf')
GLTF_MIXTURE = os.path.join(GLTF_DIR, 'mixture.cl')
GLTF_SHARED = {'mixture.cl', 'fresnel.cl'}
# Each component's term of f and pdf, called in GLTF_EVAL_ORDER rather than GLTF_COMPONENTS' order
COMPONENT_EVAL = ('void', ['const Bsdf*', 'const GltfAtWo*', 'float3', 'float3', 'GltfEval*'])


def component_violations(sources, dispatch_path):
    """Disagreements between GLTF_COMPONENTS, GLTF_EVAL_ORDER and the component files among
    sources (path -> text of the program's files)."""
    found = []
    text = strip_comments(sources.get(GLTF_MIXTURE, ''))
    names = [e[1] for e in list_entries(macro_body(text, 'GLTF_COMPONENTS') or '') if len(e) == 3]
    order = [e[0] for e in list_entries(macro_body(text, 'GLTF_EVAL_ORDER') or '')]
    if not names:
        return [f'{GLTF_MIXTURE}: no GLTF_COMPONENTS']
    if sorted(order) != sorted(names):
        found.append(f'{GLTF_MIXTURE}: GLTF_EVAL_ORDER ({", ".join(order)}) is not GLTF_COMPONENTS\' entries '
                     f'({", ".join(names)}) each once')
    signatures = dict(COMPONENT, eval=COMPONENT_EVAL)
    for name in names:
        path = os.path.join(GLTF_DIR, name + '.cl')
        if path not in sources:
            found.append(f'GLTF_COMPONENTS entry {name}: no {path} in the program')
            continue
        defs = definitions(strip_comments(sources[path]))
        for suffix, signature in signatures.items():
            fn = f'gltf_{name}_{suffix}'
            if fn not in defs:
                found.append(f'{path}: no {fn}() (each component defines its functions in its own file)')
            elif defs[fn] != signature:
                found.append(f'{fn}: {defs[fn][0]} ({", ".join(defs[fn][1])}), not the one signature '
                             f'{signature[0]} ({", ".join(signature[1])})')
    for path in sources:
        if os.path.dirname(path) == GLTF_DIR and os.path.basename(path) not in GLTF_SHARED | {n + '.cl' for n in names}:
            found.append(f'{path}: a file of cl/bsdf/gltf/ that is no GLTF_COMPONENTS entry')
    dispatch = strip_comments(sources.get(dispatch_path, ''))
    callers = generated_callers(dispatch, 'gltf', 'eval')
    if not any(re.search(r'GLTF_EVAL_ORDER\(\s*' + c + r'\s*\)', dispatch) for c in callers):
        found.append(f'{dispatch_path}: no sum of gltf_NAME_eval generated from GLTF_EVAL_ORDER')
    return found


def planted_component_violations():
    """What component_violations misses among planted violations (empty when it finds each)."""
    mixture = ('#define GLTF_COMPONENTS(X) X(GLTF_A, a, BSDF_GLOSSY) X(GLTF_B, b, BSDF_DIFFUSE)\n'
               '#define GLTF_EVAL_ORDER(X) X(b) X(a)\n')

    def definition(name, suffix, signature):
        params = ', '.join(f'{t} p{i}' for i, t in enumerate(signature[1]))
        return f'{signature[0]} gltf_{name}_{suffix}({params}) {{{"" if signature[0] == "void" else " return 0; "}}}'

    signatures = dict(COMPONENT, eval=COMPONENT_EVAL)
    component = {n: '\n'.join(definition(n, suffix, sig) for suffix, sig in signatures.items()) for n in 'ab'}
    dispatch = os.path.join('cl', 'bsdf', 'bsdf_gltf.cl')
    base = {GLTF_MIXTURE: mixture, os.path.join(GLTF_DIR, 'a.cl'): component['a'],
            os.path.join(GLTF_DIR, 'b.cl'): component['b'],
            dispatch: '#define E(name) gltf_##name##_eval(b, g, wo, wi, &acc);\nvoid f() { GLTF_EVAL_ORDER(E) }\n'}
    cases = [
        ('a component without its file', {os.path.join(GLTF_DIR, 'b.cl'): None}),
        ('a component missing from the evaluation order', {GLTF_MIXTURE: mixture.replace(' X(a)', '')}),
        ('a function in another file', {
            os.path.join(GLTF_DIR, 'a.cl'): component['a'].split('\nvoid gltf_a_eval')[0],
            os.path.join(GLTF_DIR, 'b.cl'): component['b'] + '\n' + definition('a', 'eval', COMPONENT_EVAL)}),
        ('a term of another signature', {
            os.path.join(GLTF_DIR, 'a.cl'): component['a'].replace('GltfEval* p4', 'float* p4')}),
        ('a file that is no component', {os.path.join(GLTF_DIR, 'c.cl'): ''}),
        ('a sum not generated from the list', {dispatch: 'void f() {}\n'}),
    ]
    missed = ['the clean sources (it reports one there)'] if component_violations(base, dispatch) else []
    for what, change in cases:
        sources = {p: t for p, t in dict(base, **change).items() if t is not None}
        if not component_violations(sources, dispatch):
            missed.append(what)
    return missed


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
    measured = 'typedef union { A a; B b; } M;\n#define N sizeof(M)\n'
    if not union_violations({'u.cl': 'typedef struct { union { A a; B b; } lobe; } S;'}) or union_violations(
            {'u.cl': 'typedef struct { union { float4 words[3]; A a; } lobe; } S;'}) or union_violations(
            {'u.cl': measured}) or not union_violations({'u.cl': measured + 'void f() { M m; }\n'}):
        print('kernel_lint: the union check misses its planted violation or flags a clean union; the check is broken')
        return 1
    missed = planted_list_violations()
    if missed:
        print(f'kernel_lint: the list check misses planted violations ({"; ".join(missed)}); the check is broken')
        return 1
    missed = planted_component_violations()
    if missed:
        print(f'kernel_lint: the component check misses planted violations ({"; ".join(missed)}); the check is broken')
        return 1
    found = violations(sources) + union_violations(sources)
    program_sources = {p: t for p, t in sources.items() if p in program}
    types = os.path.join('cl', 'shared', 'device_types.h')
    gltf = os.path.join('cl', 'bsdf', 'bsdf_gltf.cl')
    found += list_violations(program_sources, types, {
        'CD_MATERIALS': (types, 'bsdf', LOBE, os.path.join('cl', 'bsdf', 'bsdf.cl'), True),
        'CD_LIGHTS': (types, 'lights', LIGHT, os.path.join('cl', 'lights', 'lights.cl'), True),
        'GLTF_COMPONENTS': (GLTF_MIXTURE, 'gltf', COMPONENT, gltf, False),
    })
    found += component_violations(program_sources, gltf)
    # Test kernels may tell types apart, but use only the listed features
    test_sources = {p: strip_comments(t) for p, t in sources.items() if p.startswith('tests' + os.sep)}
    macros = {e[1] for e in list_entries(macro_body(sources[os.path.join('cl', 'shared', 'device_types.h')],
                                                    'CD_SCENE_FEATURES') or '')}
    for path, text in test_sources.items():
        for name in sorted(set(re.findall(r'\bCD_FEATURE_\w+', text)) - macros):
            found.append(f'{path}: {name} is not in CD_SCENE_FEATURES')
    for v in found:
        print(v)
    print(f'kernel_lint: {len(sources)} files, {len(found)} violation(s)')
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main())
