"""tools/closeup_table.py at a tiny size: its options (no environment variables) on the three kinds
of close-up, against 16x8, 4-spp truths path-traced here (a second or two each)."""

import numpy as np
import pytest

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.scene.scenefile import load_scene
from tools import closeup_table
from tools.closeup_table import CLOSEUPS

SCENES = ("slit-skin1", "nose-shadow-skin1", "slabs-gap-backlit-skin1")  # a slit, a shadow, the slabs


def test_a_closeup_at_another_size_keeps_its_millimetres():
    slit = CLOSEUPS["slit-skin1"]
    small = slit.at((16, 8), 4)
    assert (small.size, small.spp, small.rr_depth) == ((16, 8), 4, slit.rr_depth)
    assert small.mm_per_px * 16 == pytest.approx(slit.mm_per_px * slit.size[0])
    assert slit.at(None, None) == slit
    with pytest.raises(SystemExit, match="no close-up slit-nothing"):
        closeup_table.main(["slit-nothing"])


def test_every_kind_of_closeup_against_a_tiny_truth(tmp_path, capsys):
    pytest.importorskip("mitsuba")
    from skinlab.truth.reference import ReferenceRequest, render_reference

    for name in SCENES:
        spec = CLOSEUPS[name].at((16, 8), 4)
        scene = load_scene(REFERENCE_SCENES / f"{name}.toml")
        render_reference(scene, ReferenceRequest(16, 8, spp=4, rr_depth=spec.rr_depth), progress=False)
    out = tmp_path / "profiles.npz"
    argv = [",".join(SCENES), "none,tsd", "--size", "16x8", "--spp", "4", "--profiles", str(out), "--edge-bins"]
    assert closeup_table.main(argv) == 0
    text = capsys.readouterr().out
    assert "no cached reference" not in text
    for name in SCENES:
        assert f"{name:24s} truth 16x8 4 spp" in text
    bins = [line for line in text.splitlines() if line.startswith("    ") and " mm (" in line]
    assert bins and all("energy" in b and "L1" in b for b in bins)  # the shadow scene's bands, per technique
    rows = [line.split()[0] for line in text.splitlines() if line.startswith("  ") and not line.startswith("    ")]
    assert rows == ["none", "tsd"] * 3
    assert "deep shadow" in text and "front slab" in text and "beyond 2 mm" in text
    with np.load(out) as z:
        assert sorted(z.files) == sorted(f"slit-skin1/{k}" for k in ("truth", "truth_a", "truth_b", "none", "tsd"))
        assert z["slit-skin1/tsd"].shape == (16, 3) and np.isfinite(z["slit-skin1/tsd"]).all()
