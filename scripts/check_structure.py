#!/usr/bin/env python3
"""check_structure.py — the layout rules of docs/architecture.md, checked:

1. The host's layers depend one way: no cycle among the folders of host/ in the graph "a
   file of folder A includes a header of folder B"; and no two modules (a .c/.h pair,
   named by its path without the extension, both files present) include each other's
   headers, in one folder or across. A folder may have a header of its own that several of
   its files implement (host/scene/scene.h): that is one component, not a cycle.
2. The table under "### The host's layers" of docs/architecture.md (columns folder, what,
   uses) is the rule for which folders a folder uses: a file of a folder of host/ includes
   headers only of its own folder and of those its row lists under "uses" (folder names
   without host/, words in parentheses aside; "everything below": every folder of the rows
   below). Headers of kernels/ and system headers go anywhere. A folder of host/ with
   sources and no row, a row with no such folder, or no table at all is a violation too.
3. No function in host/ or kernels/ is longer than 80 lines, unless the comment above it
   says why, in a line starting with "Long:".

Prints each violation and exits 1 when there is one. usage: scripts/check_structure.py [ROOT]
"""
import os
import re
import sys

MAX_LINES = 80
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def sources(root, top, exts):
    for d, _, files in os.walk(os.path.join(root, top)):
        for f in sorted(files):
            if f.endswith(exts):
                yield os.path.join(d, f)


def module_of(path, root):
    return os.path.splitext(os.path.relpath(path, root))[0]


def includes(root):
    """(including file, header as written, header's path) for each include of a header of
    host/, resolved beside the includer, then anywhere under host/ by file name, as the
    Makefile's -I flags do."""
    files = list(sources(root, "host", (".c", ".h", ".cpp")))
    by_name = {}
    for f in files:
        by_name.setdefault(os.path.basename(f), []).append(f)
    for f in files:
        with open(f, encoding="utf-8") as fh:
            text = fh.read()
        for inc in INCLUDE.findall(text):
            beside = os.path.normpath(os.path.join(os.path.dirname(f), inc))
            target = beside if os.path.exists(beside) else None
            if target is None and len(by_name.get(os.path.basename(inc), [])) == 1:
                target = by_name[os.path.basename(inc)][0]
            if target is None or not target.startswith(os.path.join(root, "host")):
                continue  # kernels/types.h and system headers are below every module
            yield f, inc, target


def include_graph(root):
    """module -> set of modules whose headers it includes (includes())."""
    graph = {}
    for f, _, target in includes(root):
        mod, dep = module_of(f, root), module_of(target, root)
        if dep != mod:
            graph.setdefault(mod, set()).add(dep)
    return graph


def cycles(graph):
    """Each cycle once, as a list of modules (Tarjan's strongly connected components)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


FUNC_START = re.compile(r"^[A-Za-z_][\w \t\*]*\b([A-Za-z_]\w*)\s*\(")


def long_functions(path):
    """(name, first line, length) of functions over MAX_LINES without a 'Long:' reason.
    Relies on the project's clang-format style: a definition starts at column 0 and its
    body's braces stand at column 0."""
    with open(path, encoding="utf-8") as fh:
        lines = fh.read().split("\n")
    found = []
    i = 0
    while i < len(lines):
        m = FUNC_START.match(lines[i])
        if m and not lines[i].startswith(("typedef", "struct", "#", "static const", "const ")):
            j = i
            while j < len(lines) and lines[j] != "{" and not lines[j].rstrip().endswith(";"):
                j += 1
            if j < len(lines) and lines[j] == "{":
                k = j + 1
                while k < len(lines) and lines[k] != "}":
                    k += 1
                length = k - i + 1
                comment = []
                c = i - 1
                while c >= 0 and lines[c].lstrip().startswith(("/*", "*", "//")):
                    comment.append(lines[c])
                    c -= 1
                reason = any(re.search(r"(^|[\s*/])Long:", l) for l in comment)
                if length > MAX_LINES and not reason:
                    found.append((m.group(1), i + 1, length))
                i = k
        i += 1
    return found


def folder_graph(graph):
    """The module graph collapsed to folders (host/, host/scene, ...), without self-loops."""
    out = {}
    for mod, deps in graph.items():
        for dep in deps:
            a, b = os.path.dirname(mod), os.path.dirname(dep)
            if a != b:
                out.setdefault(a, set()).add(b)
    return out


DOC = os.path.join("docs", "architecture.md")
LAYERS = "### The host's layers"


def uses_of(cell):
    """The folder names of a "uses" cell: backquotes, trailing slashes and words in
    parentheses dropped, "—" for none."""
    cell = re.sub(r"\([^)]*\)", "", cell).replace("`", "")
    names = [n.strip().rstrip("/") for n in cell.split(",")]
    return [n for n in names if n not in ("", "—", "-")]


def layer_table(root):
    """(rules, problems): rules maps each folder of the table under LAYERS in DOC ("| folder
    | what | uses |") to the folders it may include headers from, itself among them; None
    when there is no such table. A use names a folder without host/; "everything below" is
    every folder of the rows below."""
    try:
        with open(os.path.join(root, DOC), encoding="utf-8") as fh:
            lines = [line.rstrip() for line in fh.read().split("\n")]
    except OSError as e:
        return None, [f"{DOC}: cannot read it ({e.strerror}); its table of the host's layers "
                      "is the rule"]
    rows = []
    for line in lines[lines.index(LAYERS) + 1:] if LAYERS in lines else []:
        if line.startswith("#") or (rows and not line.startswith("|")):
            break
        if line.startswith("|"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    head = [c.lower() for c in rows[0]] if rows else []
    if "folder" not in head or "uses" not in head:
        return None, [f'{DOC}: no table "| folder | what | uses |" under "{LAYERS}"']
    problems, folders, uses = [], [], []
    for row in rows[2:]:
        if len(row) != len(head):
            problems.append(f"{DOC}: a row of the host's layers with {len(row)} cells, not "
                            f"{len(head)}: | {' | '.join(row)} |")
            continue
        folders.append(row[head.index("folder")].replace("`", "").rstrip("/"))
        uses.append(uses_of(row[head.index("uses")]))
    rules = {}
    for i, (folder, names) in enumerate(zip(folders, uses)):
        rules[folder] = {folder}
        for name in names:
            if name == "everything below":
                rules[folder].update(folders[i + 1:])
                continue
            dep = name if name.startswith("host/") else "host/" + name
            if dep not in folders:
                problems.append(f'{DOC}: the row of {folder} uses "{name}", a folder with no row')
            rules[folder].add(dep)
    return rules, problems


def layer_problems(root):
    """The table's problems (layer_table), each folder of host/ with sources and no row, each
    row with no such folder, and each include of a header from a folder its row does not
    list under "uses"."""
    rules, problems = layer_table(root)
    if rules is None:
        return problems
    files = sources(root, "host", (".c", ".h", ".cpp"))
    have = {os.path.dirname(module_of(f, root)) for f in files}
    for folder in sorted(have - set(rules)):
        problems.append(f'{folder}: no row in the table under "{LAYERS}" of {DOC}')
    for folder in sorted(set(rules) - have):
        problems.append(f'{DOC}: a row for {folder}, which has no sources')
    for f, inc, target in includes(root):
        a, b = os.path.dirname(module_of(f, root)), os.path.dirname(module_of(target, root))
        if a in rules and b not in rules[a]:
            allowed = ", ".join(sorted(rules[a] - {a})) or "no other folder"
            problems.append(f"{os.path.relpath(f, root)} includes {inc} "
                            f"({os.path.relpath(target, root)}): {a} uses {allowed}, not {b} "
                            f'(the table under "{LAYERS}" of {DOC})')
    return problems


def mutual_pairs(root, graph):
    """Pairs of modules with a .c (or .cpp) each that include each other's headers."""
    def has_source(mod):
        return any(os.path.exists(os.path.join(root, mod + e)) for e in (".c", ".cpp"))
    pairs = set()
    for a, deps in graph.items():
        for b in deps:
            if a < b and a in graph.get(b, ()) and has_source(a) and has_source(b):
                pairs.add((a, b))
    return sorted(pairs)


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    bad = 0
    graph = include_graph(root)
    for cyc in cycles(folder_graph(graph)):
        print("include cycle among host folders: " + " <-> ".join(cyc))
        bad += 1
    for a, b in mutual_pairs(root, graph):
        print(f"include cycle among host modules: {a} <-> {b}")
        bad += 1
    for problem in layer_problems(root):
        print(problem)
        bad += 1
    for f in list(sources(root, "host", (".c", ".cpp"))) + list(sources(root, "kernels", (".cl",))):
        for name, line, length in long_functions(f):
            print(f"{os.path.relpath(f, root)}:{line}: {name} is {length} lines (over {MAX_LINES}; "
                  "split it, or say why in a 'Long:' line of the comment above it)")
            bad += 1
    print(f"check_structure: {bad} problem{'s' if bad != 1 else ''}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
