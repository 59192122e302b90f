#!/usr/bin/env python3
"""The architecture checks of the test command (Python 3.11, standard library only).

    python3 scripts/architecture.py --write   # regenerate the crate table in docs/architecture.md
    python3 scripts/architecture.py --check   # every check below; exit 1 on any failure

--check fails when
  1. the crate table between `<!-- crates:begin -->` and `<!-- crates:end -->` in
     docs/architecture.md differs from what `cargo metadata --no-deps` gives (crate, path, the
     workspace crates it depends on as normal dependencies, lines of .rs code under src/), or a
     workspace crate is not named in the chapter outside that table;
  2. a crate's modules import each other in a cycle (below);
  3. a .rs file under a crate's src/ has more than MAX_FILE_LINES lines;
  4. a crate's tests/ folder builds more than MAX_TEST_BINARIES integration-test binaries
     (top-level tests/*.rs plus tests/*/main.rs);
  5. code of one crate reaches two modules deep into another workspace crate
     (`other_crate::module::submodule::...`): each crate exports a curated surface.

Checks 2-4 cover the workspace's crates and the separate workspaces embedded/*/ (found by
their Cargo.toml, not through cargo, which would resolve their target-only dependencies).

The module graph (check 2). Each crate root (src/lib.rs, src/main.rs, src/bin/*) is read by
following its `mod` declarations (`#[path]` honoured inside the crate's src/); items under
`#[cfg(test)]`, `#[cfg(all(test, ..))]` (test modules, test helpers) or `#[cfg(doc)]` (imports
for rustdoc links) are dropped. Every path
that names a module of the crate is collected: `use` trees, and `crate::`, `super::`, `self::`,
child-module and imported-name paths in the code; names re-exported by a `use` (`crate::SimError`
for `pub use error::SimError`) resolve to the module that holds the item. A reference from
module A to module B is an edge between the two children of their closest common ancestor that
contain A and B: so the top-level modules of the crate form one graph, and the children of each
folder module another. A strongly connected component of any of these graphs is an import
cycle; each is printed with one shortest cycle through each of its modules, every edge with the
first place (file:line) that makes it. References between a module and its own descendants
(a mod.rs re-exporting its children, a child using its parent's items) are not cycles here.
Limits: macros are not expanded, and a name brought in by a glob (`use super::*`) is followed
only when it is used with a path.
"""
from __future__ import annotations

import argparse
import collections
import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CHAPTER = ROOT / "docs" / "architecture.md"
BEGIN, END = "<!-- crates:begin -->", "<!-- crates:end -->"
MAX_FILE_LINES = 500
MAX_TEST_BINARIES = 3
# The rule on test binaries is for the simulator's crates, whose binaries each link rapier,
# foxglove and plotters. The core's tests link nalgebra alone and ship with its package
# (`cargo package -p tvmd-core`), one file per property checked.
TEST_BINARY_EXEMPT = {"tvmd-core"}
REGENERATE = "python3 scripts/architecture.py --write"


# ---------------------------------------------------------------------------------------------
# Crates


def workspace_crates() -> list[dict]:
    """The workspace's crates from `cargo metadata`: name, dir, workspace deps (normal)."""
    out = subprocess.run(
        ["cargo", "metadata", "--format-version", "1", "--no-deps"],
        cwd=ROOT, check=True, capture_output=True, text=True,
    ).stdout
    meta = json.loads(out)
    members = set(meta["workspace_members"])
    pkgs = [p for p in meta["packages"] if p["id"] in members]
    names = {p["name"] for p in pkgs}
    crates = []
    for p in pkgs:
        deps = sorted({d["name"] for d in p["dependencies"]
                       if d["kind"] is None and d.get("path") and d["name"] in names})
        crates.append({"name": p["name"], "dir": Path(p["manifest_path"]).parent, "deps": deps})
    return crates


def embedded_crates() -> list[dict]:
    crates = []
    for manifest in sorted((ROOT / "embedded").glob("*/Cargo.toml")):
        m = re.search(r'^\s*name\s*=\s*"([^"]+)"', manifest.read_text(), re.M)
        crates.append({"name": m.group(1) if m else manifest.parent.name, "dir": manifest.parent,
                       "deps": []})
    return crates


def rel(path: Path) -> str:
    r = path.relative_to(ROOT).as_posix()
    return r if r else "."


def src_lines(crate: dict) -> int:
    return sum(len(f.read_text().splitlines()) for f in sorted((crate["dir"] / "src").rglob("*.rs")))


def crate_table(crates: list[dict]) -> str:
    by_name = {c["name"]: c for c in crates}
    depth: dict[str, int] = {}

    def level(name: str) -> int:
        if name not in depth:
            depth[name] = 0
            depth[name] = 1 + max((level(d) for d in by_name[name]["deps"]), default=-1)
        return depth[name]

    rows = ["| crate | path | depends on (workspace crates) | lines in `src/` |",
            "|---|---|---|---:|"]
    for c in sorted(crates, key=lambda c: (level(c["name"]), c["name"])):
        deps = ", ".join(f"`{d}`" for d in c["deps"]) or "-"
        rows.append(f"| `{c['name']}` | `{rel(c['dir'])}` | {deps} | {src_lines(c):,} |")
    return "\n".join(rows)


def without_counts(text: str) -> str:
    """The chapter with the crate table's last column (lines in `src/`) blanked."""
    head, rest = text.split(BEGIN, 1)
    table, tail = rest.split(END, 1)
    rows = [re.sub(r"\| [0-9,]+ \|$", "| |", row) for row in table.splitlines()]
    return head + "\n".join(rows) + tail


def check_table(crates: list[dict], write: bool) -> list[str]:
    text = CHAPTER.read_text()
    if text.count(BEGIN) != 1 or text.count(END) != 1 or text.index(BEGIN) > text.index(END):
        return [f"{rel(CHAPTER)}: needs one `{BEGIN}` ... `{END}` block for the crate table"]
    head, rest = text.split(BEGIN)
    _, tail = rest.split(END)
    table = f"{BEGIN}\n{crate_table(crates)}\n{END}"
    new = head + table + tail
    if write:
        if new != text:
            CHAPTER.write_text(new)
            print(f"wrote the crate table of {rel(CHAPTER)}")
        return []
    errors = []
    # The line counts move with every edit: the check holds the crates, their paths and their
    # dependencies to the code, and `--write` refreshes the counts with them.
    if without_counts(new) != without_counts(text):
        errors.append(f"{rel(CHAPTER)}: the crate table is stale; regenerate it with `{REGENERATE}`")
    prose = head + tail
    for c in crates:
        if not re.search(rf"(?<![\w-]){re.escape(c['name'])}(?![\w-])", prose):
            errors.append(f"{rel(CHAPTER)}: workspace crate `{c['name']}` is not named in the "
                          "chapter (outside the generated table)")
    return errors


# ---------------------------------------------------------------------------------------------
# Rust source: comments and literals blanked, then tokens


RAW_STRING = re.compile(r'b?r(#*)"')
IDENT_CHAR = re.compile(r"\w")


def blank(text: str) -> tuple[str, dict[int, str]]:
    """Comments and the insides of string and char literals replaced by spaces (newlines kept,
    so offsets and line numbers stay); returns the string literals by their start offset."""
    out = list(text)
    strings: dict[int, str] = {}
    i, n = 0, len(text)

    def wipe(a: int, b: int) -> None:
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            wipe(i, j)
            i = j
        elif c in "br" and (m := RAW_STRING.match(text, i)) and not (i and IDENT_CHAR.match(text[i - 1])):
            close = '"' + m.group(1)
            j = text.find(close, m.end())
            j = n if j < 0 else j
            strings[i] = text[m.end():j]
            wipe(m.end(), j)
            i = j + len(close)
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            strings[i] = text[i + 1:j]
            wipe(i + 1, j)
            i = j + 1
        elif c == "'":
            if text.startswith("\\", i + 1):
                j = i + 2
                while j < n and text[j] != "'":
                    j += 1
                wipe(i + 1, j)
                i = j + 1
            elif i + 2 < n and text[i + 2] == "'":
                wipe(i + 1, i + 2)
                i += 3
            else:
                i += 1  # a lifetime
        else:
            i += 1
    return "".join(out), strings


TOKEN = re.compile(r"\$?[A-Za-z_][A-Za-z0-9_]*|::|[#!\[\](){};*,<>=]|\S")


class Tok:
    __slots__ = ("v", "pos")

    def __init__(self, v: str, pos: int):
        self.v, self.pos = v, pos


def tokens(code: str) -> list[Tok]:
    return [Tok(m.group(0), m.start()) for m in TOKEN.finditer(code)]


def matching(toks: list[Tok], i: int) -> int:
    """Index of the bracket closing the one at i."""
    pairs = {"(": ")", "[": "]", "{": "}"}
    stack = [pairs[toks[i].v]]
    for j in range(i + 1, len(toks)):
        v = toks[j].v
        if v in pairs:
            stack.append(pairs[v])
        elif v in (")", "]", "}"):
            stack.pop()
            if not stack:
                return j
    return len(toks) - 1


def is_test_cfg(attr: str) -> bool:
    """`#[cfg(test)]`, `#[cfg(all(test, ..))]` or `#[cfg(doc)]` (an import for rustdoc links)."""
    a = attr.replace(" ", "")
    return a in ("cfg(test)", "cfg(doc)") or (a.startswith("cfg(all(") and "test" in a[8:-2].split(","))


def item_end(toks: list[Tok], i: int) -> int:
    """Index of the last token of the item starting at i (its `;`, or its body's `}`)."""
    semicolon_only = False
    j = i
    while j < len(toks):
        v = toks[j].v
        if v in ("const", "static", "use", "type", "let") and not (
                v == "const" and j + 1 < len(toks) and toks[j + 1].v in ("fn", "unsafe", "async")):
            semicolon_only = True
        if v == ";":
            return j
        if v in ("(", "["):
            j = matching(toks, j)
        elif v == "{":
            j = matching(toks, j)
            if not semicolon_only:
                return j
        j += 1
    return len(toks) - 1


def use_tree(toks: list[Tok], i: int, prefix: list[str], out: list) -> int:
    """Parse a use tree from i; append (segments, name, is_glob, pos). Returns the next index."""
    segs = list(prefix)
    start = toks[i].pos if i < len(toks) else 0
    while i < len(toks):
        v = toks[i].v
        if v == "::":
            i += 1
        elif v == "{":
            end = matching(toks, i)
            i += 1
            while i < end:
                i = use_tree(toks, i, segs, out)
                if i < end and toks[i].v == ",":
                    i += 1
            return end + 1
        elif v == "*":
            out.append((segs, None, True, toks[i].pos))
            return i + 1
        elif re.match(r"[A-Za-z_]", v):
            segs.append(v)
            i += 1
            if i < len(toks) and toks[i].v == "::":
                continue
            name = segs[-1]
            if i + 1 < len(toks) and toks[i].v == "as":
                name = toks[i + 1].v
                i += 2
            if segs[-1] == "self":
                segs = segs[:-1]
                name = segs[-1] if name == "self" and segs else name
            if segs:
                out.append((segs, name, False, start))
            return i
        else:
            return i
    return i


class CrateRoot:
    """One crate root's module tree: modules, their files, `use` name maps and references."""

    def __init__(self, crate: dict, root_file: Path):
        self.crate, self.root_file = crate, root_file
        self.src = crate["dir"] / "src"
        self.modules: dict[tuple, Path] = {}
        self.names: dict[tuple, dict[str, tuple]] = collections.defaultdict(dict)
        self.globs: dict[tuple, list[tuple]] = collections.defaultdict(list)
        self.refs: list[tuple] = []  # (module, path segments, file, line)
        self.files: set[Path] = set()
        self.memo: dict[tuple, tuple | None] = {}
        self.read_module((), root_file, mod_rs=True)

    def read_module(self, ctx: tuple, path: Path, mod_rs: bool) -> None:
        self.modules[ctx] = path
        if not path.is_file() or not path.resolve().is_relative_to(self.src.resolve()):
            return  # a #[path] file of another crate: a leaf here
        self.files.add(path)
        text = path.read_text()
        code, strings = blank(text)
        toks = tokens(code)
        own_dir = path.parent if mod_rs else path.parent / path.stem
        src = {"path": path, "code": code, "strings": strings, "dir": own_dir,
               "file_dir": path.parent}
        self.items(toks, 0, len(toks), ctx, src)

    def items(self, toks: list[Tok], i: int, end: int, ctx: tuple, src: dict) -> None:
        attrs: list[tuple[str, int, int]] = []
        while i < end:
            v = toks[i].v
            if v == "#" and i + 2 < end and toks[i + 1].v == "!" and toks[i + 2].v == "[":
                close = matching(toks, i + 2)
                if is_test_cfg(src["code"][toks[i + 3].pos:toks[close].pos]):
                    return  # #![cfg(test)]: the whole module is a test module
                i = close + 1
                continue
            if v == "#" and i + 1 < end and toks[i + 1].v == "[":
                close = matching(toks, i + 1)
                attrs.append((src["code"][toks[i + 2].pos:toks[close].pos], toks[i].pos, toks[close].pos))
                i = close + 1
                continue
            if any(is_test_cfg(a) for a, _, _ in attrs):
                i = item_end(toks, i) + 1
                attrs = []
                continue
            if v == "pub":
                i += 1
                if i < end and toks[i].v == "(":
                    i = matching(toks, i) + 1
                continue
            if v == "mod" and i + 2 < end and re.match(r"\w", toks[i + 1].v):
                name = toks[i + 1].v
                if toks[i + 2].v == ";":
                    self.declared(ctx + (name,), attrs, src)
                    i += 3
                elif toks[i + 2].v == "{":
                    close = matching(toks, i + 2)
                    self.modules[ctx + (name,)] = src["path"]
                    self.items(toks, i + 3, close, ctx + (name,), src)
                    i = close + 1
                else:
                    i += 1
                attrs = []
                continue
            if v == "use":
                semi = item_end(toks, i)
                found: list = []
                use_tree(toks[:semi], i + 1, [], found)
                for segs, name, glob, pos in found:
                    if segs and segs[0] == "::":
                        continue
                    if glob:
                        self.globs[ctx].append(tuple(segs))
                    elif name and name != "_":
                        self.names[ctx][name] = tuple(segs)
                    self.ref(ctx, segs, src, pos)
                i = semi + 1
                attrs = []
                continue
            if v == "{":
                close = matching(toks, i)
                self.items(toks, i + 1, close, ctx, src)
                i = close + 1
                attrs = []
                continue
            if v in (";", "}"):
                attrs = []
                i += 1
                continue
            if re.match(r"[A-Za-z_]", v) and i + 2 < end and toks[i + 1].v == "::" \
                    and (i == 0 or toks[i - 1].v != "::"):
                segs, j = [v], i + 1
                while j + 1 < end and toks[j].v == "::" and re.match(r"[A-Za-z_]", toks[j + 1].v):
                    segs.append(toks[j + 1].v)
                    j += 2
                self.ref(ctx, segs, src, toks[i].pos)
                i = j
                continue
            i += 1

    def declared(self, ctx: tuple, attrs: list, src: dict) -> None:
        """A `mod name;`: read its file (`#[path]`, `name.rs` or `name/mod.rs`)."""
        name = ctx[-1]
        for text, start, end in attrs:
            lits = [s for p, s in src["strings"].items() if start < p < end]
            if re.match(r"path\s*=", text) and lits:
                target = (src["file_dir"] / lits[0]).resolve()
                self.read_module(ctx, target, mod_rs=target.name == "mod.rs")
                return
        for cand, mod_rs in ((src["dir"] / f"{name}.rs", False), (src["dir"] / name / "mod.rs", True)):
            if cand.is_file():
                self.read_module(ctx, cand, mod_rs)
                return
        self.modules[ctx] = src["dir"] / f"{name}.rs"  # missing file: cargo reports it

    def ref(self, ctx: tuple, segs: list[str], src: dict, pos: int) -> None:
        line = src["code"].count("\n", 0, pos) + 1
        self.refs.append((ctx, tuple(segs), src["path"], line))

    # -- resolution ----------------------------------------------------------------------------

    def resolve(self, ctx: tuple, segs: tuple, depth: int = 0) -> tuple | None:
        """The module a path names or holds the item it names; None if outside the crate."""
        key = (ctx, segs)
        if key not in self.memo:
            self.memo[key] = None  # re-entered through globs or re-exports: outside
            self.memo[key] = self.resolve_uncached(ctx, segs, depth)
        return self.memo[key]

    def resolve_uncached(self, ctx: tuple, segs: tuple, depth: int) -> tuple | None:
        if depth > 12 or not segs:
            return None
        first, rest = segs[0], segs[1:]
        if first in ("crate", "self", "super"):
            cur = () if first == "crate" else ctx
            if first == "super":
                rest = segs
            while rest and rest[0] == "super":
                if not cur:
                    return None
                cur, rest = cur[:-1], rest[1:]
        elif ctx + (first,) in self.modules:
            cur = ctx + (first,)
        elif first in self.names.get(ctx, {}):
            return self.resolve(ctx, self.names[ctx][first] + rest, depth + 1)
        else:
            for g in self.globs.get(ctx, []):
                gm = self.resolve(ctx, g, depth + 1)
                if gm is not None and (gm + (first,) in self.modules or first in self.names.get(gm, {})):
                    return self.resolve(gm, (first,) + rest, depth + 1)
            return None
        for k, seg in enumerate(rest):
            if cur + (seg,) in self.modules:
                cur = cur + (seg,)
            elif seg in self.names.get(cur, {}):
                return self.resolve(cur, self.names[cur][seg] + rest[k + 1:], depth + 1) or cur
            else:
                for g in self.globs.get(cur, []):
                    gm = self.resolve(cur, g, depth + 1)
                    if gm is not None and gm != cur and (gm + (seg,) in self.modules or seg in self.names.get(gm, {})):
                        return self.resolve(gm, (seg,) + rest[k + 1:], depth + 1) or gm
                return cur
        return cur

    def cycles(self) -> list[str]:
        # level (a module) -> child -> child -> first evidence
        graph: dict[tuple, dict[str, dict[str, str]]] = collections.defaultdict(lambda: collections.defaultdict(dict))
        for ctx, segs, path, line in self.refs:
            target = self.resolve(ctx, segs)
            if target is None:
                continue
            k = 0
            while k < len(ctx) and k < len(target) and ctx[k] == target[k]:
                k += 1
            if k == len(ctx) or k == len(target):
                continue  # one contains the other
            a, b = ctx[k], target[k]
            edges = graph[ctx[:k]][a]
            edges.setdefault(b, f"{rel(path)}:{line} ({'::'.join(segs)})")
        report = []
        for level in sorted(graph):
            for scc in strongly_connected(graph[level]):
                report.append(self.describe(level, scc, graph[level]))
        return report

    def describe(self, level: tuple, scc: list[str], edges: dict) -> str:
        where = "crate" + "".join(f"::{m}" for m in level)
        root = "" if self.root_file.name == "lib.rs" else f" (root {rel(self.root_file)})"
        lines = [f"import cycle in {self.crate['name']}{root} among the children of {where}: "
                 + ", ".join(sorted(scc))]
        seen: set[tuple] = set()
        for start in sorted(scc):
            path = shortest_cycle(start, edges, set(scc))
            key = tuple(sorted(zip(path, path[1:])))
            if not path or key in seen:
                continue
            seen.add(key)
            lines.append("  " + " -> ".join(path))
            for a, b in zip(path, path[1:]):
                lines.append(f"      {a} -> {b}: {edges[a][b]}")
        return "\n".join(lines)


def strongly_connected(edges: dict[str, dict[str, str]]) -> list[list[str]]:
    """Tarjan's strongly connected components of more than one node."""
    nodes = sorted(set(edges) | {b for e in edges.values() for b in e})
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, {})):
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

    for v in nodes:
        if v not in index:
            visit(v)
    return out


def shortest_cycle(start: str, edges: dict, within: set[str]) -> list[str]:
    prev: dict[str, str] = {}
    queue = collections.deque([start])
    while queue:
        v = queue.popleft()
        for w in sorted(edges.get(v, {})):
            if w not in within:
                continue
            if w == start:
                path = [v]
                while path[-1] != start:
                    path.append(prev[path[-1]])
                return [start] + path[::-1][1:] + [start] if v != start else [start, start]
            if w not in prev:
                prev[w] = v
                queue.append(w)
    return []


def crate_roots(crate: dict) -> list[Path]:
    src = crate["dir"] / "src"
    roots = [src / "lib.rs", src / "main.rs"] + sorted((src / "bin").glob("*.rs")) \
        + sorted((src / "bin").glob("*/main.rs"))
    return [r for r in roots if r.is_file()]


# ---------------------------------------------------------------------------------------------


# `krate::module::submodule::` with snake_case modules, not a turbofish (`f::<T>`).
DEEP_PATH = re.compile(r"\b(tvmd_[a-z0-9_]+)::([a-z][a-z0-9_]*)::([a-z][a-z0-9_]*)::(?!<)")


def deep_paths(crate: dict, names: set[str]) -> list[str]:
    """Paths from this crate's code two modules deep into another workspace crate."""
    own = crate["name"].replace("-", "_")
    found = []
    for folder in ("src", "tests", "benches", "examples"):
        for f in sorted((crate["dir"] / folder).rglob("*.rs")):
            for k, line in enumerate(f.read_text().splitlines(), 1):
                if line.lstrip().startswith("//"):
                    continue
                for m in DEEP_PATH.finditer(line):
                    if m.group(1) != own and m.group(1) in names and m.group(2) != "nalgebra":
                        found.append(f"{rel(f)}:{k}: `{m.group(0)}` reaches two modules deep "
                                     f"into {m.group(1)}; export it from the crate's root")
    return found


def check_crate(crate: dict) -> list[str]:
    errors = []
    reached: set[Path] = set()
    for root in crate_roots(crate):
        tree = CrateRoot(crate, root)
        reached |= tree.files
        errors += tree.cycles()
    for f in sorted((crate["dir"] / "src").rglob("*.rs")):
        n = len(f.read_text().splitlines())
        if n > MAX_FILE_LINES:
            errors.append(f"{rel(f)}: {n} lines (at most {MAX_FILE_LINES} per file under src/)")
    tests = crate["dir"] / "tests"
    if tests.is_dir() and crate["name"] not in TEST_BINARY_EXEMPT:
        bins = sorted(tests.glob("*.rs")) + sorted(tests.glob("*/main.rs"))
        if len(bins) > MAX_TEST_BINARIES:
            errors.append(f"{rel(tests)}: {len(bins)} integration-test binaries (at most "
                          f"{MAX_TEST_BINARIES}): " + ", ".join(rel(b) for b in bins))
    return errors


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="regenerate the crate table")
    mode.add_argument("--check", action="store_true", help="run every check")
    args = ap.parse_args()
    crates = workspace_crates()
    errors = check_table(crates, write=args.write)
    if args.write:
        return 0
    print(f"crate table and names: {'ok' if not errors else 'FAILED'}")
    names = {c["name"].replace("-", "_") for c in crates}
    for crate in crates + embedded_crates():
        found = check_crate(crate)
        if crate in crates:
            found += deep_paths(crate, names)
        print(f"{crate['name']} ({rel(crate['dir'])}): {'ok' if not found else f'{len(found)} problem(s)'}")
        errors += found
    if errors:
        print("\n" + "\n".join(errors), file=sys.stderr)
        print(f"\narchitecture check failed: {len(errors)} problem(s)", file=sys.stderr)
        return 1
    print("architecture check passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
