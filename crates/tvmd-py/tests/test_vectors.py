"""The loader of the reference vectors (``vectors.py``): the repository's file by default, the
file named by ``$TVMD_REFERENCE_VECTORS`` when set, and an error naming the path otherwise.

The variable is checked in child processes, so this process's environment is never changed.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import vectors

TESTS = Path(__file__).resolve().parent
PROBE = (
    "import vectors\n"
    "print('path=' + str(vectors.VECTORS_PATH))\n"
    "print('thrust=%r' % vectors.VECTORS['gimbal'][0]['thrust'])\n"
)


def _changed_copy(tmp_path, thrust):
    data = json.loads(vectors.DEFAULT_PATH.read_text())
    data["gimbal"][0]["thrust"] = thrust
    path = tmp_path / "changed.json"
    path.write_text(json.dumps(data))
    return path


def _probe(value):
    env = dict(os.environ)
    env[vectors.ENV_VAR] = str(value)
    return subprocess.run([sys.executable, "-c", PROBE], cwd=TESTS, env=env, capture_output=True, text=True)


def test_default_is_the_repository_file():
    assert vectors.vectors_path({}) == vectors.DEFAULT_PATH
    assert vectors.vectors_path({vectors.ENV_VAR: ""}) == vectors.DEFAULT_PATH
    assert vectors.DEFAULT_PATH.relative_to(TESTS.parents[1]) == Path("tvmd-core/tests/data/core_vectors.json")
    data = vectors.load_vectors(vectors.DEFAULT_PATH)
    assert all(len(data[k]) > 0 for k in vectors.FAMILIES)


def test_loader_returns_the_data_of_the_file_it_is_given(tmp_path):
    path = _changed_copy(tmp_path, 12345.5)
    assert vectors.vectors_path({vectors.ENV_VAR: str(path)}) == path
    assert vectors.load_vectors(path)["gimbal"][0]["thrust"] == 12345.5
    assert vectors.load_vectors(vectors.DEFAULT_PATH)["gimbal"][0]["thrust"] != 12345.5


@pytest.mark.parametrize("content", [None, '{"gimbal": [', "[]", '{"gimbal": []}'])
def test_missing_or_malformed_files_are_errors_naming_the_path(tmp_path, content):
    path = tmp_path / "bad.json"
    if content is not None:
        path.write_text(content)
    with pytest.raises(vectors.VectorFileError, match="bad.json"):
        vectors.load_vectors(path)


def test_environment_variable_selects_the_file(tmp_path):
    path = _changed_copy(tmp_path, 6789.25)
    run = _probe(path)
    assert run.returncode == 0, run.stderr
    assert f"path={path}" in run.stdout
    assert "thrust=6789.25" in run.stdout


def test_environment_variable_naming_a_missing_file_fails_with_its_path(tmp_path):
    missing = tmp_path / "no-such-vectors.json"
    run = _probe(missing)
    assert run.returncode != 0
    assert "VectorFileError" in run.stderr and str(missing) in run.stderr
