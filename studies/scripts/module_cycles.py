#!/usr/bin/env python3
"""Import cycles between the folders of a crate's `src/`.

Reads every `.rs` file under SRC (default `studies/src`), takes the module
paths it names (`use crate::...`, `use super::...`, `use self::...` and
inline `crate::a::b` paths; test modules excluded: `*_tests.rs`, `tests.rs`
and `#[cfg(test)] mod NAME { ... }` blocks), maps each to the file that
defines the module, and reports

* the strongly connected components of the file graph that span more than
  one folder, and
* the cycles of the folder graph (a folder is the first path component under
  SRC; a file at SRC's root is its own folder),

each with the file edges that make it. Exit status 1 when a cycle crosses a
folder.

    python3 studies/scripts/module_cycles.py [SRC]
"""
import os
import re
import sys


def strip_tests(text):
    """Drops `#[cfg(test)] mod x { ... }` blocks and comments."""
    text = re.sub(r"//[^\n]*", "", text)
    out, i = [], 0
    pat = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{")
    while True:
        m = pat.search(text, i)
        if not m:
            out.append(text[i:])
            break
        out.append(text[i:m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    return "".join(out)


def expand(tree):
    """`a::{b, c::{d, e}}` -> ['a::b', 'a::c::d', 'a::c::e']."""
    tree = re.sub(r"\s+", "", tree)
    m = re.match(r"^([^{]*?)(?:::)?\{(.*)\}$", tree)
    if not m:
        return [re.sub(r"\bas\w+$", "", tree)]
    prefix, body = m.group(1), m.group(2)
    parts, depth, cur = [], 0, ""
    for ch in body:
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += {"{": 1, "}": -1}.get(ch, 0)
        cur += ch
    parts.append(cur)
    res = []
    for p in parts:
        if not p:
            continue
        for e in expand(p):
            res.append(prefix + "::" + e if prefix else e)
    return res


def module_of(rel):
    parts = rel[:-3].split("/")
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return tuple(p for p in parts if p != "bin")


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "studies/src"
    files = {}
    for root, _, names in os.walk(src):
        for n in names:
            if not n.endswith(".rs") or n.endswith("_tests.rs") or n == "tests.rs":
                continue
            rel = os.path.relpath(os.path.join(root, n), src)
            if rel.startswith("bin/"):
                continue
            files[module_of(rel)] = rel
    edges = {}
    for mod, rel in files.items():
        text = strip_tests(open(os.path.join(src, rel)).read())
        is_mod_file = rel.endswith("mod.rs") or rel == "lib.rs"
        here = mod if is_mod_file else mod[:-1]  # the module `self` of a child file
        paths = []
        for u in re.finditer(r"\buse\s+([^;]+);", text):
            paths += expand(u.group(1))
        paths += re.findall(r"\b(?:crate|super)(?:::\w+)+", text)
        targets = set()
        for p in paths:
            segs = p.split("::")
            if segs[0] == "crate":
                base, rest = (), segs[1:]
            elif segs[0] in ("super", "self"):
                base = mod if segs[0] == "self" else (mod[:-1])
                rest = segs[1:]
                while rest and rest[0] == "super":
                    base, rest = base[:-1], rest[1:]
            else:
                continue
            # the longest prefix that is a file's module
            best = None
            for k in range(len(rest), -1, -1):
                cand = base + tuple(rest[:k])
                if cand in files:
                    best = cand
                    break
            if best is not None and best != mod and best != ():
                targets.add(best)
        del here
        edges[mod] = targets

    def folder(m):
        return m[0] if m else "lib"

    def tarjan(nodes, succ):
        index, low, on, stack, out, n = {}, {}, set(), [], [], [0]

        def visit(v):
            index[v] = low[v] = n[0]
            n[0] += 1
            stack.append(v)
            on.add(v)
            for w in sorted(succ.get(v, ())):
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
                out.append(sorted(comp))

        sys.setrecursionlimit(10000)
        for v in sorted(nodes):
            if v not in index:
                visit(v)
        return [c for c in out if len(c) > 1]

    name = lambda m: "::".join(m) or "crate"
    bad = 0
    print(f"{len(files)} files under {src} (test modules excluded)")
    print("\nFile-level cycles that span more than one folder:")
    for comp in tarjan(list(files), edges):
        folders = sorted({folder(m) for m in comp})
        if len(folders) > 1:
            bad += 1
            print(f"  {len(comp)} files in {len(folders)} folders ({', '.join(folders)}):")
            print("    " + ", ".join(name(m) for m in comp))
    if not bad:
        print("  none")
    fsucc = {}
    why = {}
    for a, ts in edges.items():
        for b in ts:
            fa, fb = folder(a), folder(b)
            if fa != fb:
                fsucc.setdefault(fa, set()).add(fb)
                why.setdefault((fa, fb), []).append(f"{name(a)} -> {name(b)}")
    print("\nFolder-level cycles:")
    comps = tarjan({folder(m) for m in files}, fsucc)
    for comp in comps:
        print(f"  {', '.join(comp)}:")
        for a in comp:
            for b in comp:
                if (a, b) in why:
                    print(f"    {a} -> {b}: {'; '.join(sorted(why[(a, b)]))}")
    if not comps:
        print("  none")
    return 1 if comps or bad else 0


if __name__ == "__main__":
    sys.exit(main())
