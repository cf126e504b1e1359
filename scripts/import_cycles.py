#!/usr/bin/env python3
"""Import cycles between the files of the crate.

Reads every `.rs` file under SRC (default: the repository's `src/`), maps each file to its module
path (`src/io/gltf/read.rs` -> `io::gltf::read`), and collects the paths it names through
`crate::`, `super::` and `self::` (in `use` lines and inline paths such as `super::strength::f`).
Each path is resolved to the longest module prefix that is a file of the crate. Within every
directory module the edges between its children (a file, or a sub-folder taken as one) form a
graph; a strongly connected component of more than one child is a cycle and is printed. Test
modules (`mod tests` blocks and `tests.rs` files) are left out: tests may reach anywhere.

Exit status 1 when there is a cycle, 0 when there is none.
"""
import os
import re
import sys

src = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "src"))

modules = {}  # module path tuple -> file
for dirpath, _, files in os.walk(src):
    for name in files:
        if not name.endswith(".rs"):
            continue
        rel = os.path.relpath(os.path.join(dirpath, name), src)
        parts = rel[:-3].split(os.sep)
        if parts[-1] in ("mod", "lib", "main"):
            parts = parts[:-1]
        if parts and parts[-1] == "tests":
            continue
        modules[tuple(parts)] = os.path.join(dirpath, name)

path_re = re.compile(r"\b(crate|super|self)((?:::\w+)+)")


def strip_tests(text):
    """The text without `#[cfg(test)] mod ... { ... }` blocks."""
    out = []
    i = 0
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*(pub(\(\w+\))?\s+)?mod\s+\w+\s*\{", text[i:])
        if not m:
            out.append(text[i:])
            break
        start = i + m.start()
        out.append(text[i:start])
        depth = 0
        j = i + m.end() - 1
        while j < len(text):
            if text[j] == "{":
                depth += 1
            elif text[j] == "}":
                depth -= 1
                if depth == 0:
                    break
            j += 1
        i = j + 1
    return "".join(out)


def strip_comments(text):
    return re.sub(r"//[^\n]*", "", text)


def resolve(current, kind, rest):
    """Absolute module path tuple named from module `current`."""
    names = rest.strip(":").split("::")
    if kind == "crate":
        base = []
    elif kind == "self":
        base = list(current)
    else:
        base = list(current[:-1])
        while names and names[0] == "super":
            base = base[:-1]
            names = names[1:]
    full = base + names
    for k in range(len(full), 0, -1):
        if tuple(full[:k]) in modules:
            return tuple(full[:k])
    return None


edges = {}
for mod, path in modules.items():
    text = strip_comments(strip_tests(open(path, encoding="utf-8").read()))
    # `use super::{a, b::c}` groups: expand the first level of braces.
    for m in re.finditer(r"\b(crate|super|self)((?:::\w+)*)::\{([^}]*)\}", text):
        for item in m.group(3).split(","):
            item = item.strip().split(" as ")[0]
            if item and item != "self":
                target = resolve(mod, m.group(1), m.group(2) + "::" + item.split("::")[0])
                if target:
                    edges.setdefault(mod, set()).add(target)
    for m in path_re.finditer(text):
        target = resolve(mod, m.group(1), m.group(2))
        if target:
            edges.setdefault(mod, set()).add(target)

cycles = []
parents = {m[:-1] for m in modules if m} | {()}
for parent in sorted(parents):
    depth = len(parent)
    children = {m[: depth + 1] for m in modules if len(m) > depth and m[:depth] == parent}
    graph = {c: set() for c in children}
    for src_mod, targets in edges.items():
        if len(src_mod) <= depth or src_mod[:depth] != parent:
            continue
        a = src_mod[: depth + 1]
        for t in targets:
            if len(t) > depth and t[:depth] == parent:
                b = t[: depth + 1]
                if a != b:
                    graph[a].add(b)
    # Tarjan's strongly connected components.
    index, low, stack, on, comps = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
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
                comps.append(comp)

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    for comp in comps:
        names = sorted("::".join(c) for c in comp)
        cycles.append((("::".join(parent) or "crate"), names))

for parent, names in cycles:
    print(f"cycle in {parent}: {' <-> '.join(names)}")
if cycles:
    sys.exit(1)
print(f"no import cycle between the {len(modules)} module files under {os.path.relpath(src)}")
