"""The catalogue presets and tvmd.afs_atlas through the bindings."""

import math

import numpy as np
import pytest

import tvmd


def test_every_preset_builds_and_hovers():
    names = tvmd.Team.preset_names()
    assert len(names) == 20 and names[0] == "a3-con" and "t10-inc" in names
    for name in names:
        team = tvmd.Team.preset(name)
        assert team.arrangement == ("Con" if name.endswith("con") else "Inc")
        assert team.hover_capability().capable, name
    # The paper's square is the a4-inc preset; `_` and case are accepted.
    assert np.allclose(tvmd.Team.preset("A4_INC").positions, tvmd.Team.a4_inc().positions)
    with pytest.raises(ValueError, match="unknown preset"):
        tvmd.Team.preset("a11-inc")


def test_afs_atlas_a4_inc(tmp_path):
    row = tvmd.afs_atlas("a4-inc", heights=[1.0], directions=8, certify_heights=3, plots=tmp_path)
    assert row["team"] == "a4-inc" and row["n"] == 4 and row["can_hover"]
    lo, hi = row["ceiling"]
    assert lo <= hi and abs(lo - 2.0) < 1e-6
    hover = row["heights"][0]
    # The cone is conservative at hover: ratios below one, fully sound.
    assert 0.6 < hover["ratio"][0] <= hover["ratio"][1] < 0.9
    assert hover["soundness"][0] > 1 - 1e-9
    s_lo, s_hi = row["certified"]
    assert 0.5 < s_lo <= s_hi <= 1.0
    assert (tmp_path / "a4-inc.png").stat().st_size > 10_000
    # A failure the team survives gives a smaller ceiling.
    degraded = tvmd.afs_atlas("a6-inc", failed=[0], heights=[1.0], directions=8, certify_heights=2)
    assert degraded["n"] == 5 and degraded["ceiling"][1] < 2.0


def test_afs_atlas_rejects_bad_arguments():
    with pytest.raises(ValueError, match="unknown team") as refused:
        tvmd.afs_atlas("a42")
    # The names it lists are the ones it takes (not "all", which it refuses).
    assert "all" not in str(refused.value) and "a4-inc" in str(refused.value)
    with pytest.raises(ValueError, match="one team"):
        tvmd.afs_atlas("all")
    with pytest.raises(ValueError, match="directions"):
        tvmd.afs_atlas("a4-inc", directions=2)
    with pytest.raises(ValueError, match="relaxation"):
        tvmd.afs_atlas("a4-inc", relaxation=math.nan)
    with pytest.raises(ValueError, match="failed"):
        tvmd.afs_atlas("a4-inc", failed=[7])
    with pytest.raises(ValueError, match="failed"):
        tvmd.afs_atlas("a4-inc", failed=[-1])
    with pytest.raises(ValueError, match="directions"):
        tvmd.afs_atlas("a4-inc", directions=-3)
    with pytest.raises(ValueError, match="`certify_heights` must be >= 2 and <= 200"):
        tvmd.afs_atlas("a4-inc", certify_heights=1)
    with pytest.raises(ValueError, match="heights"):
        tvmd.afs_atlas("a4-inc", heights=[math.inf])
