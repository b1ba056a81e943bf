"""The close-ups in the accuracy ledger (issue 21): a scene's own truth settings from its [measure] table
(size, spp, Russian roulette depth) and the close-up measures it declares (skinlab/bench/closeup.py:
the tails of a line profile, the deep shadow, each mesh's energy), on tiny copies of three close-ups
against tiny truths path-traced here (a few seconds), and the measures on arrays."""

import math
import re
from dataclasses import replace

import numpy as np
import pytest

from skinlab.bench import accuracy as acc
from skinlab.bench import closeup
from skinlab.bench.truth_ledger import REFERENCE_SCENES, TruthSpec, scene_truth_spec

MESHES = REFERENCE_SCENES.parent.parent / "meshes"
HEADS = REFERENCE_SCENES.parent.parent / "lee-perry-smith"


def test_tail_shares_on_a_profile_and_per_pixel_agree():
    prof = np.zeros((10, 3))
    prof[4:6] = 1.0  # the slit's two middle columns
    prof[0] = prof[9] = 0.5  # light 4.5 columns away on both sides
    got = closeup.tail_fractions(prof, mm_per_px=1.0)
    assert got.shape == (3, 3)
    assert got[0] == pytest.approx([1 / 3] * 3)  # beyond 2 mm: the two outer columns, 1 of 3
    assert got[1:] == pytest.approx(np.zeros((2, 3)))
    img = np.repeat(prof[None], 4, axis=0)  # 4 rows of the same profile
    dist = np.repeat(((np.arange(10) + 0.5 - 5) * 1.0)[None], 4, axis=0)
    assert closeup.tail_shares(img, dist) == pytest.approx(got)
    dist[0, 0] = np.nan  # no surface there: not counted
    assert np.isfinite(closeup.tail_shares(img, dist)).all()
    assert closeup.largest([0.1, -0.3, math.nan]) == -0.3 and math.isnan(closeup.largest([math.nan]))
    assert math.isnan(closeup.region_level(img, np.zeros((4, 10), bool), np.ones((4, 10), bool)))


def _slit_regions(w: int = 41, h: int = 4, mask=None):
    """CloseupRegions of a slit down the middle of a w x h image, columns 1 mm apart (no scene needed)."""
    from skinlab.scene.measure import MeasureSpec

    spec = MeasureSpec(profile="line", profile_origin=(0.0, 0.0, 0.0), profile_axis=(1.0, 0.0, 0.0))
    across = np.repeat((np.arange(w) - w // 2.0)[None], h, axis=0)
    return closeup.CloseupRegions(None, spec, (w, h), across, np.ones((h, w), bool) if mask is None else mask)


def test_each_channel_tail_is_its_own():
    """Red wide, blue narrow (skin's): red's tail beyond each distance is larger than blue's, luminance's
    between them; a one-channel image's other channels, an empty mask and a black image stay finite."""
    import warnings

    cu = _slit_regions()
    x = np.abs(np.arange(41) - 20.0)
    img = np.zeros((4, 41, 4))  # an alpha channel too: not a colour
    img[..., 0] = np.exp(-x / 4.0)  # red: 4 mm
    img[..., 1] = np.exp(-x / 2.0)
    img[..., 2] = np.exp(-x / 0.8)  # blue: 0.8 mm
    img[..., 3] = 1.0
    v = cu.values(img)
    assert set(v) == {*closeup.TAIL_KEYS, *closeup.TAIL_CHANNEL_KEYS}
    assert closeup.tail_key(2.0) == "truth_tail_2mm" and closeup.tail_key(10.0, "b") == "truth_tail_10mm_b"
    for d in closeup.TAIL_MM:
        r, g, b = (v[closeup.tail_key(d, c)] for c in closeup.CHANNELS)
        assert r > g > b >= 0
        assert b < v[closeup.tail_key(d)] < r
        assert r == pytest.approx(float((img[..., 0] * (x > d)).sum() / img[..., 0].sum()))  # red's own share
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        red = img.copy()
        red[..., 1:3] = 0.0  # light in red alone: the others have no tail (0, not NaN)
        v = cu.values(red)
        assert all(v[closeup.tail_key(d, c)] == 0.0 for d in closeup.TAIL_MM for c in "gb")
        assert v[closeup.tail_key(2.0, "r")] > 0  # and luminance's is red's
        assert all(v[closeup.tail_key(d, "r")] == pytest.approx(v[closeup.tail_key(d)]) for d in closeup.TAIL_MM)
        for got in (cu.values(np.zeros_like(img)), _slit_regions(mask=np.zeros((4, 41), bool)).values(img)):
            assert set(got) == {*closeup.TAIL_KEYS, *closeup.TAIL_CHANNEL_KEYS}
            assert all(math.isfinite(x) for x in got.values())
        diff = {k: fn(img) for k, fn in cu.measures(img * 2.0).items()}  # twice as bright: the same shares
        assert diff.keys() == v.keys() and max(map(abs, diff.values())) < 1e-12


def test_a_scene_without_truth_settings_keeps_the_sweeps():
    from skinlab.scene.scenefile import load_scene

    spec = TruthSpec((32, 32), 16, passes=2)
    assert scene_truth_spec(load_scene("head-skin1-matched"), spec) == spec
    own = scene_truth_spec(load_scene("slit-marble"), spec)
    assert (own.size, own.spp, own.rr_depth, own.passes) == ((256, 16), 64, 1024, 2)
    assert own.request().rr_depth == 1024 and own.command_options == "--size 256x16 --spp 64 --passes 2 --rr-depth 1024"


def _tiny_copy(tmp_path, name: str, size: str) -> str:
    """The close-up's scene file with a tiny truth of its own (4 spp; its meshes' paths made absolute)."""
    text = (REFERENCE_SCENES / f"{name}.toml").read_text(encoding="utf-8")
    text = text.replace("../../meshes", str(MESHES)).replace("../../lee-perry-smith", str(HEADS))
    text = text.replace("\nsubdivide = 2\n", "\n")  # the scan as it is: these measure the plumbing, not the facets
    head, measure = text.split("[measure]\n")
    keep = [ln for ln in measure.splitlines() if not ln.startswith(("truth_size", "truth_spp", "truth_rr_depth"))]
    p = tmp_path / f"{name}.toml"
    p.write_text(head + f'[measure]\ntruth_size = "{size}"\ntruth_spp = 4\n' + "\n".join(keep) + "\n")
    return str(p)


def test_closeups_in_the_ledger_at_their_own_truth_size(ctx, tmp_path, monkeypatch):
    pytest.importorskip("mitsuba")
    pytest.importorskip("trimesh")
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))
    scenes = (_tiny_copy(tmp_path, "slit-skin1", "32x4"), _tiny_copy(tmp_path, "slabs-gap-backlit-skin1", "16x8"))
    sweep = replace(acc.TINY, size=(16, 16), frames=1, warmup=1, scenes=scenes)
    res = acc.run_sweep(sweep, tmp_path / "out", peer=False, progress=False, images=False, references=True)
    rows = {(r["scene"], r["setting"]): r for r in res["rows"]}
    truths = res["meta"]["truth"]["scenes"]
    assert truths["slit-skin1"]["size"] == [32, 4]
    assert truths["slabs-gap-backlit-skin1"]["size"] == [16, 8] and truths["slit-skin1"]["spp"] == 4
    for (scene, _), r in rows.items():
        assert r["status"] == "ok", r["error"]
        assert math.isfinite(r["truth_rel_l1_block"])
        tails = [r[k] for k in (*closeup.TAIL_KEYS, *closeup.TAIL_CHANNEL_KEYS)]
        assert all(map(math.isfinite, tails)) == (scene == "slit-skin1")
        assert any(map(math.isfinite, tails)) == (scene == "slit-skin1")
        assert math.isnan(r["truth_deep_shadow"])
        assert math.isfinite(r["truth_mesh_energy"]) == (scene == "slabs-gap-backlit-skin1")
        if scene == "slit-skin1":
            assert all(math.isfinite(r[f"{k}_sigma"]) for k in (*closeup.TAIL_KEYS, *closeup.TAIL_CHANNEL_KEYS))
            assert len(r["jackknife"]["truth_tail_2mm"]) == 2  # a 2-pass truth: two groups
            assert len(r["jackknife"]["truth_tail_2mm_r"]) == 2
    slabs = next(r for (s, _), r in rows.items() if s == "slabs-gap-backlit-skin1")
    assert slabs["truth_mesh_energy"] >= 0 and math.isfinite(slabs["truth_mesh_energy_sigma"])
    assert slabs["truth_mesh_energy_each"].startswith("front ") and "; back " in slabs["truth_mesh_energy_each"]
    assert set(truths["slit-skin1"]["closeup"]) == {*closeup.TAIL_KEYS, *closeup.TAIL_CHANNEL_KEYS}
    assert "truth_tail_2mm_r" in (tmp_path / "out" / "ledger.csv").read_text().splitlines()[0].split(",")
    md = (tmp_path / "out" / "ledger.md").read_text()
    for says in ("| slit-skin1 |", "32x4", "Close-ups: the share of the light", "slit-skin1 > 2mm (truth",
                 "Close-ups: each visible mesh's energy", "Close-ups: the tails per channel",
                 "slit-skin1 > 10mm (truth ", "`truth_tail_5mm_g_sigma`"):  # fmt: skip
        assert says in md, says
    # the luminance's tails, then each channel's: a cell R/G/B +- the largest standard error
    assert md.index("Close-ups: the share of the light") < md.index("Close-ups: the tails per channel")
    per_channel = md.split("Close-ups: the tails per channel", 1)[1].split("\n\n", 2)[1].splitlines()
    assert per_channel[0].count("slit-skin1 > ") == 3 and "slabs" not in per_channel[0]
    assert re.search(r"\| [+-]\d+\.\d\d/[+-]\d+\.\d\d/[+-]\d+\.\d\d \+- \d+\.\d\d \|", per_channel[2])
    assert "Close-ups: the deep shadow's level" not in md  # no scene here declares it
    page = (tmp_path / "out" / "ledger.html").read_text()
    sections = {s.split("</h2>", 1)[0]: s for s in page.split("<h2>")[1:]}
    slit = next(v for k, v in sections.items() if k.startswith("slit-skin1"))
    slabs = next(v for k, v in sections.items() if k.startswith("slabs-gap-backlit-skin1"))
    assert "Close-ups: the share of the light" in slit and "slit-skin1 &gt; 2mm (truth" in slit
    assert "each visible mesh&#x27;s energy" in slabs and "Close-ups: the share of the light" not in slabs
    assert "Close-ups: the tails per channel" in slit and "tails per channel" not in slabs
    assert re.search(r"<td>[+-]\d+\.\d\d/[+-]\d+\.\d\d/[+-]\d+\.\d\d \u00b1 \d+\.\d\d</td>", slit)
    assert "the deep shadow&#x27;s level" not in page


def test_the_deep_shadow_against_a_tiny_truth(tmp_path, monkeypatch):
    """The nose's deep shadow (ray-cast regions) measured on its tiny truth: the truth's level with its
    standard error, a frame's level minus the truth's with its own; without it declared, not measured."""
    pytest.importorskip("mitsuba")
    pytest.importorskip("trimesh")
    from skinlab.bench.truth_ledger import closeup_truth, load_truth, truth_context, truth_errors
    from skinlab.scene.scenefile import load_scene

    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))
    scene = load_scene(_tiny_copy(tmp_path, "nose-shadow-skin1", "24x24"))
    spec = scene_truth_spec(scene, TruthSpec((32, 32), 16, passes=2))
    assert (spec.size, spec.spp) == ((24, 24), 4)
    truth = load_truth(scene, spec, render=True, progress=False)
    tc = truth_context(scene, truth, None)
    level, sigma = closeup_truth(tc)["truth_deep_shadow"]
    assert 0 <= level < 0.5 and sigma >= 0  # the shadow is far darker than the lit cheek
    brighter = truth_errors(truth.image * 1.5, tc)  # the whole frame 1.5 x: the same level
    assert brighter["truth_deep_shadow"] == pytest.approx(0.0, abs=1e-9)
    assert math.isnan(brighter["truth_tail_2mm"]) and math.isnan(brighter["truth_mesh_energy"])
    lifted = truth.image.copy()
    lifted[..., :3] += 0.05 * truth.image[..., :3].max()  # light in the shadow: its level rises
    assert truth_errors(lifted, tc)["truth_deep_shadow"] > 0
    scene.measure = replace(scene.measure, deep_shadow=False)
    assert truth_context(scene, truth, None).closeup is None
