"""tools/truth_table.py at a tiny size: its options (no environment variables) and the ledger's measures."""

import pytest

from skinlab.bench.sweep import QUICK
from skinlab.bench.truth_ledger import REFERENCE_SCENES, TruthSpec, load_truth, truth_errors
from skinlab.scene.scenefile import load_scene
from tools import truth_table


def test_truth_spec_parses_and_names_what_it_expected():
    assert truth_table.truth_spec("96:256") == TruthSpec((96, 96), 256)
    gpu = TruthSpec((96, 96), 131072, variant="cuda_ad_rgb", seed=1)
    assert truth_table.truth_spec("96:131072:cuda_ad_rgb:1") == gpu
    with pytest.raises(SystemExit):
        truth_table.parser().parse_args(["--truth", "192"])


def test_rows_are_the_ledgers_truth_measures(capsys):
    pytest.importorskip("mitsuba")
    scene = load_scene(REFERENCE_SCENES / "slab-edge-skin1.toml")
    truth = load_truth(scene, TruthSpec((8, 8), 4), render=True, progress=False)  # a few seconds at 8x8
    assert truth is not None
    assert truth_table.main(["slab-edge-skin1,bunny-marble", "none", "--truth", "8:4", "--supersample", "1"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "frames at 1 x 1 samples per pixel, box-filtered"
    row = next(line for line in out if line.startswith("slab-edge-skin1"))
    # the printed 4x4 figure is the ledger's truth_rel_l1_block of the same frame
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings

    r = Renderer(create_headless_context())
    st = RenderSettings.for_technique("none", 8, 8, shadow_size=QUICK.shadow_size)
    img = r.render(scene, st, readback=("hdr",)).hdr
    r.release()
    want = truth_errors(img, truth)["truth_rel_l1_block"]
    assert f"4x4 {100 * want:6.1f}%" in row, (row, want)
    # a scene without a cached reference of that size says so instead of a row
    assert "bunny-marble: no cached 8x8, 4-spp scalar_rgb reference (seed 0)" in out
