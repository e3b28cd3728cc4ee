#!/usr/bin/env python3
"""check_structure.py — the layout rules of docs/architecture.md, checked:

1. The host's layers depend one way: no cycle among the folders of host/ in the graph "a
   file of folder A includes a header of folder B"; and no two modules (a .c/.h pair,
   named by its path without the extension, both files present) include each other's
   headers, in one folder or across. A folder may have a header of its own that several of
   its files implement (host/scene/scene.h): that is one component, not a cycle.
2. No function in host/ or kernels/ is longer than 80 lines, unless the comment above it
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
    for f in list(sources(root, "host", (".c", ".cpp"))) + list(sources(root, "kernels", (".cl",))):
        for name, line, length in long_functions(f):
            print(f"{os.path.relpath(f, root)}:{line}: {name} is {length} lines (over {MAX_LINES}; "
                  "split it, or say why in a 'Long:' line of the comment above it)")
            bad += 1
    print(f"check_structure: {bad} problem{'s' if bad != 1 else ''}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
