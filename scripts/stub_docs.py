#!/usr/bin/env python3
"""The docstrings of the Python bindings' Rust callables, written from the stubs (one source).

The stubs (``crates/tvmd-py/python/tvmd/_tvmd.pyi`` and ``sim.pyi``) document the callables of
``tvmd`` and ``tvmd.sim`` at length (arguments, shapes, units, errors). A Rust callable whose
docstring is the stub's includes it as ``#[doc = include_str!("../docstrings/<name>.txt")]``
(``<name>`` the public name: ``tvmd.Team.wrench``, ``tvmd.sim.run``); this script writes those
files from the stubs: a function's or method's docstring (the longest of its overloads), a
class's docstring followed by its ``__init__``'s. So ``help()``, ``inspect.getdoc`` and Jupyter
show what the stub says.

    python3 scripts/stub_docs.py          # (re)write crates/tvmd-py/docstrings/*.txt
    python3 scripts/stub_docs.py --check  # fail if a file is missing, stale or unused

``crates/tvmd-py/tests/test_help.py`` runs ``--check`` and compares the built module's
docstrings with the files. Stdlib only.
"""

from __future__ import annotations

import ast
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CRATE = ROOT / "crates" / "tvmd-py"
DOCS = CRATE / "docstrings"
STUBS = {"tvmd.sim": CRATE / "python" / "tvmd" / "sim.pyi", "tvmd": CRATE / "python" / "tvmd" / "_tvmd.pyi"}
INCLUDE = re.compile(r'include_str!\("\.\./docstrings/([\w.]+)\.txt"\)')


def referenced() -> list[str]:
    """The names the Rust sources include, sorted."""
    names = set()
    for f in (CRATE / "src").rglob("*.rs"):
        names.update(INCLUDE.findall(f.read_text()))
    return sorted(names)


def stub_nodes(path: Path) -> dict[str, list[ast.AST]]:
    found: dict[str, list[ast.AST]] = {}

    def visit(body: list[ast.stmt], prefix: str) -> None:
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                found.setdefault(prefix + node.name, []).append(node)
                if isinstance(node, ast.ClassDef):
                    visit(node.body, f"{prefix}{node.name}.")

    visit(ast.parse(path.read_text()).body, "")
    return found


def docstring(name: str) -> str:
    """The stub's docstring of the public callable `name`."""
    module = next(m for m in STUBS if name.startswith(m + "."))  # tvmd.sim before tvmd
    qualname = name[len(module) + 1 :]
    nodes = stub_nodes(STUBS[module])
    if qualname not in nodes:
        raise SystemExit(f"error: `{name}` is not declared in {STUBS[module].relative_to(ROOT)}")
    docs = [ast.get_docstring(n) or "" for n in nodes[qualname]]
    doc = max(docs, key=len)
    if isinstance(nodes[qualname][0], ast.ClassDef):
        init = [ast.get_docstring(n) or "" for n in nodes.get(f"{qualname}.__init__", [])]
        if init and max(init, key=len):
            doc = f"{doc}\n\n{max(init, key=len)}"
    if not doc:
        raise SystemExit(f"error: `{name}` has no docstring in the stub")
    return doc + "\n"


def main(argv: list[str]) -> int:
    check = "--check" in argv
    names = referenced()
    wanted = {f"{n}.txt": docstring(n) for n in names}
    problems = []
    for file, text in wanted.items():
        path = DOCS / file
        if check:
            if not path.exists() or path.read_text() != text:
                problems.append(f"{path.relative_to(ROOT)} is missing or differs from the stub")
        else:
            DOCS.mkdir(exist_ok=True)
            path.write_text(text)
    for path in sorted(DOCS.glob("*.txt")) if DOCS.exists() else []:
        if path.name not in wanted:
            if check:
                problems.append(f"{path.relative_to(ROOT)} is not included by any Rust source")
            else:
                path.unlink()
    for p in problems:
        print(f"error: {p}", file=sys.stderr)
    if problems:
        print("run `python3 scripts/stub_docs.py` to rewrite them from the stubs", file=sys.stderr)
        return 1
    print(f"{len(names)} docstrings {'checked' if check else 'written'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
