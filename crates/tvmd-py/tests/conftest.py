"""Shared pytest setup: import path for the helper modules and the agreement report.

``reference_impl`` (the NumPy reference) and ``vectors`` (the loader of the reference vectors in
``crates/tvmd-core/tests/data/``, or of ``$TVMD_REFERENCE_VECTORS``) live beside the tests. The
``agreement`` fixture records the largest differences between the bindings and the reference;
they are printed in the terminal summary (no ``-s`` needed).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))


class Agreement:
    """Largest absolute and normwise-relative differences per compared quantity."""

    def __init__(self):
        self.rows = {}

    def record(self, name, actual, expected):
        a = np.asarray(actual, dtype=float)
        e = np.asarray(expected, dtype=float)
        diff = float(np.max(np.abs(a - e))) if a.size else 0.0
        scale = float(np.max(np.abs(e))) if e.size else 0.0
        rel = diff / scale if scale > 0.0 else diff
        count, max_abs, max_rel = self.rows.get(name, (0, 0.0, 0.0))
        self.rows[name] = (count + 1, max(max_abs, diff), max(max_rel, rel))


_AGREEMENT = Agreement()


@pytest.fixture(scope="session")
def agreement():
    return _AGREEMENT


def pytest_terminal_summary(terminalreporter):
    if not _AGREEMENT.rows:
        return
    tr = terminalreporter
    tr.section("tvmd bindings vs NumPy reference (max |diff| and max |diff|/max|ref| per quantity)")
    tr.write_line(f"{'quantity':<42} {'samples':>8} {'max abs':>11} {'max rel':>11}")
    for name in sorted(_AGREEMENT.rows):
        count, max_abs, max_rel = _AGREEMENT.rows[name]
        tr.write_line(f"{name:<42} {count:>8} {max_abs:>11.3e} {max_rel:>11.3e}")
