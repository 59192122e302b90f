"""Loading of the shared reference vectors (``shared/reference/core_vectors.json``).

Shared by ``test_reference_impl.py`` (the NumPy reference) and ``test_bindings.py`` (the
bindings). The vectors are looked up in ``$TVMD_SHARED/reference/`` if the environment variable
is set, else in the ``shared`` directory beside the repository checkout.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

RTOL = 1e-9  # relative tolerance of the vectors (README of the vectors)
ATOL = 1e-12  # absolute floor for entries that are 0 up to round-off (e.g. -8e-17 in M)
PLANNER_TOL = 1e-6  # bisection: theta in rad, R_d entries


def shared_dir() -> Path:
    env = os.environ.get("TVMD_SHARED")
    if env:
        return Path(env)
    return Path(__file__).resolve().parents[3].parent / "shared"


VECTORS_PATH = shared_dir() / "reference" / "core_vectors.json"
VECTORS = json.loads(VECTORS_PATH.read_text()) if VECTORS_PATH.is_file() else None

needs_vectors = pytest.mark.skipif(VECTORS is None, reason=f"test vectors not found at {VECTORS_PATH}")


def cases(key):
    """Parameters (one per case) of a vector family; a single skipped one without vectors."""
    if VECTORS is None:
        return [pytest.param(None, id=key, marks=pytest.mark.skip(reason=f"no test vectors at {VECTORS_PATH}"))]
    return [pytest.param(c, id=f"{key}-{i}") for i, c in enumerate(VECTORS[key])]
