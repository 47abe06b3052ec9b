#!/usr/bin/env python3
"""Structural checks run by CI (.ci/run):

1. No import cycles between the top-level modules of the root crate (src/): every
   `crate::<module>` path in a module's files is an edge; the re-exports `crate::brownian`,
   `crate::packing` and `crate::particle_fluid` count as `pipelines`. Tarjan's strongly
   connected components must all be single modules.
2. No Rust source file over 600 lines (anywhere in the workspace but target/).
3. Shared code names no pipeline: the driver, scene parser, replay, CLI and recorder hold no
   string literal "packing", "brownian" or "particle_fluid" and import no pipeline module
   (comments, doc examples and #[cfg(test)] modules aside).
4. Every repository path a document names in backquotes (`src/...`, `tests/...`, `docs/...`,
   and the other top-level folders) exists, so README.md and docs/ do not point at moved files.

Exit 1 with every finding listed, 0 when clean.
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SRC = os.path.join(ROOT, "src")
ALIASES = {"brownian": "pipelines", "packing": "pipelines", "particle_fluid": "pipelines"}
MAX_LINES = 600
PIPELINE_NAMES = ["packing", "brownian", "particle_fluid"]
SHARED = [
    "src/sim.rs",
    "src/replay.rs",
    "src/error.rs",
    "src/scene",
    "src/cli",
    "plugins/src/recorder.rs",
    "plugins/src/app.rs",
    "plugins/src/group.rs",
]


def rust_files(path):
    if os.path.isfile(path):
        yield path
        return
    for d, dirs, files in os.walk(path):
        dirs[:] = [x for x in dirs if x not in ("target", ".git")]
        for f in files:
            if f.endswith(".rs"):
                yield os.path.join(d, f)


def code_lines(text):
    """Lines of code: comments dropped, #[cfg(test)] modules at the end of a file cut."""
    out = []
    for line in text.splitlines():
        s = line.strip()
        if s.startswith("#[cfg(test)]"):
            # test modules follow their attribute; files keep them last by convention
            if "mod " in text[text.find(line):text.find(line) + 200]:
                break
        if s.startswith("//"):
            continue
        out.append(re.sub(r"//.*$", "", line))
    return out


def top_modules():
    mods = {}
    for entry in os.listdir(SRC):
        p = os.path.join(SRC, entry)
        if entry in ("lib.rs", "main.rs"):
            continue
        name = entry[:-3] if entry.endswith(".rs") else entry
        if os.path.isdir(p) or entry.endswith(".rs"):
            mods.setdefault(name, []).append(p)
    return mods


def import_cycles():
    mods = top_modules()
    graph = {m: set() for m in mods}
    for m, paths in mods.items():
        for p in paths:
            for f in rust_files(p):
                if f.endswith("tests.rs"):
                    continue
                for line in code_lines(open(f, encoding="utf-8").read()):
                    for dep in re.findall(r"crate::([a-z_][a-z0-9_]*)", line):
                        dep = ALIASES.get(dep, dep)
                        if dep in graph and dep != m:
                            graph[m].add(dep)
    index, low, stack, on, sccs = {}, {}, [], set(), []
    counter = [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
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
            sccs.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            strong(v)
    return [c for c in sccs if len(c) > 1], graph


def long_files():
    found = []
    for f in rust_files(ROOT):
        n = sum(1 for _ in open(f, encoding="utf-8"))
        if n > MAX_LINES:
            found.append(f"{os.path.relpath(f, ROOT)}: {n} lines (max {MAX_LINES})")
    return found


def pipeline_names_in_shared_code():
    found = []
    for entry in SHARED:
        for f in rust_files(os.path.join(ROOT, entry)):
            if f.endswith("tests.rs"):
                continue
            for i, line in enumerate(code_lines(open(f, encoding="utf-8").read()), 1):
                for name in PIPELINE_NAMES:
                    if f'"{name}"' in line:
                        found.append(f"{os.path.relpath(f, ROOT)}: literal \"{name}\": {line.strip()}")
                if re.search(r"crate::(pipelines|brownian|packing|particle_fluid)\b", line):
                    found.append(f"{os.path.relpath(f, ROOT)}: imports a pipeline: {line.strip()}")
    return found


TOP_DIRS = ("src/", "systems/", "plugins/", "components/", "record/", "tests/", "scripts/",
            "examples/", "scenes/", "docs/", ".ci/")


def stale_doc_paths():
    found = []
    docs = [os.path.join(ROOT, "README.md")]
    for d, dirs, files in os.walk(ROOT):
        dirs[:] = [x for x in dirs if x not in ("target", ".git")]
        docs += [os.path.join(d, f) for f in files if f.endswith(".md")]
    for f in sorted(set(docs)):
        text = open(f, encoding="utf-8").read()
        for m in re.finditer(r"`([A-Za-z0-9_./-]+)`", text):
            p = m.group(1)
            if not p.startswith(TOP_DIRS) or "*" in p:
                continue
            if not os.path.exists(os.path.join(ROOT, p.rstrip("/"))):
                found.append(f"{os.path.relpath(f, ROOT)}: names `{p}`, which does not exist")
    return found


def main():
    problems = []
    cycles, graph = import_cycles()
    for c in cycles:
        problems.append("import cycle between top-level modules: " + " <-> ".join(c))
    problems += long_files()
    problems += pipeline_names_in_shared_code()
    problems += stale_doc_paths()
    print(f"modules: {len(graph)}; edges: {sum(len(v) for v in graph.values())}")
    if "-v" in sys.argv:
        for m in sorted(graph):
            print(f"  {m} -> {', '.join(sorted(graph[m]))}")
    for p in problems:
        print("  " + p)
    if problems:
        print(f"{len(problems)} structural problem(s)")
        return 1
    print("structure ok: no import cycles, no file over 600 lines, no pipeline name in shared code, "
          "no stale path in the documents")
    return 0


if __name__ == "__main__":
    sys.exit(main())
