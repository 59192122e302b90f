"""The stubs (``python/tvmd/_tvmd.pyi``, ``python/tvmd/sim.pyi``) match the built module.

``mypy.stubtest`` compares every name, signature, default and property of the stubs with the
runtime module; ``stubtest_allowlist.txt`` lists the few things it cannot see (each with a
comment). Every class, method and function of the stubs carries a docstring.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

import tvmd

HERE = Path(__file__).resolve().parent
STUBS = [Path(tvmd.__file__).with_name(name) for name in ("_tvmd.pyi", "sim.pyi")]


def test_stubtest(tmp_path):
    pytest.importorskip("mypy")
    # The installed package is checked; mypy's cache goes to a temporary directory.
    env = {**os.environ, "MYPYPATH": "", "MYPY_CACHE_DIR": str(tmp_path / "mypy_cache")}
    result = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "tvmd", "--allowlist", str(HERE / "stubtest_allowlist.txt")],
        cwd=HERE, env=env, capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("stub", STUBS, ids=lambda p: p.name)
def test_stub_docstrings(stub):
    missing = []

    def visit(node, prefix):
        for item in node.body:
            if isinstance(item, (ast.ClassDef, ast.FunctionDef)):
                name = f"{prefix}{item.name}"
                if item.name != "__new__" and ast.get_docstring(item) is None:
                    missing.append(name)
                if isinstance(item, ast.ClassDef):
                    visit(item, name + ".")

    visit(ast.parse(stub.read_text()), "")
    assert not missing, missing
