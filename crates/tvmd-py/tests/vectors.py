"""Loading of the reference vectors (``crates/tvmd-core/tests/data/core_vectors.json``).

Shared by ``test_reference_impl.py`` (the NumPy reference) and ``test_bindings.py`` (the
bindings); the Rust suite reads the same file. Provenance, tolerances and format are in
``crates/tvmd-core/tests/data/README.md``. The environment variable ``TVMD_REFERENCE_VECTORS``,
when set and not empty, names another file of the same format. A missing or malformed file is
an error naming its path (raised at import, so the suite fails instead of skipping).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path

import pytest

RTOL = 1e-9  # relative tolerance of the vectors (README of the vectors)
ATOL = 1e-12  # absolute floor for entries that are 0 up to round-off (e.g. -8e-17 in M)
PLANNER_TOL = 1e-6  # bisection: theta in rad, R_d entries

ENV_VAR = "TVMD_REFERENCE_VECTORS"
# crates/tvmd-py/tests/vectors.py -> crates/tvmd-core/tests/data/
DEFAULT_PATH = Path(__file__).resolve().parents[2] / "tvmd-core" / "tests" / "data" / "core_vectors.json"
FAMILIES = ("gimbal", "effectiveness", "afs_semi_axes", "force_projection", "attitude_planner")


class VectorFileError(RuntimeError):
    """The vector file is missing or malformed; the message names the path."""


def vectors_path(environ: Mapping[str, str] = os.environ) -> Path:
    """``$TVMD_REFERENCE_VECTORS`` when set and not empty, else the repository's file."""
    value = environ.get(ENV_VAR, "")
    return Path(value) if value else DEFAULT_PATH


def load_vectors(path: Path) -> dict:
    """Reads and checks a vector file (every family a non-empty list of cases)."""
    what = f"reference vectors {path}"
    try:
        text = Path(path).read_text()
    except OSError as e:
        raise VectorFileError(f"cannot read {what}: {e}") from e
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise VectorFileError(f"{what} are not valid JSON: {e}") from e
    if not isinstance(data, dict):
        raise VectorFileError(f"{what}: the top level is not an object")
    for key in FAMILIES:
        cases_ = data.get(key)
        if not isinstance(cases_, list) or not cases_:
            raise VectorFileError(f"{what}: `{key}` is not a non-empty list of cases")
    return data


VECTORS_PATH = vectors_path()
VECTORS = load_vectors(VECTORS_PATH)


def needs_vectors(test):
    """Kept for the tests that use it: the vectors are always present now (or the import fails)."""
    return test


def cases(key):
    """Parameters (one per case) of a vector family."""
    return [pytest.param(c, id=f"{key}-{i}") for i, c in enumerate(VECTORS[key])]
