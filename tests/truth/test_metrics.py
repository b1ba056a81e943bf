"""The metrics that see what a viewer sees (skinlab/truth/metrics.py), where scattering lives
(skinlab/truth/regions.py), the scene file's [measure] table and `skinlab compare`."""

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from skinlab.truth import metrics, regions

ROOT = Path(__file__).resolve().parents[2]
SLAB_EDGE = ROOT / "skinlab" / "assets" / "scenes" / "reference" / "slab-edge-skin1.toml"


def _img(rgb, h=8, w=8, alpha=1.0):
    x = np.zeros((h, w, 4), np.float32)
    x[..., :3] = rgb
    x[..., 3] = alpha
    return x


def test_relative_l1_energy_and_their_definitions():
    ref = _img((1.0, 2.0, 4.0))
    img = ref.copy()
    img[:4, :, 0] = 1.5  # the red of half the pixels 50 % too bright
    img[:, :, 2] = 3.0  # blue 25 % too dark everywhere
    # sum |a - b| / sum b over pixels and channels: (32 * 0.5 + 64 * 1) / (64 * 7)
    assert metrics.rel_l1(img, ref) == pytest.approx((32 * 0.5 + 64) / (64 * 7))
    assert metrics.rel_l1_rgb(img, ref) == pytest.approx([0.25, 0.0, 0.25])
    assert metrics.energy(img, ref) == pytest.approx([0.25, 0.0, -0.25])
    # only the truth's object pixels count
    ref[4:, :, 3] = 0.0
    assert metrics.rel_l1_rgb(img, ref) == pytest.approx([0.5, 0.0, 0.25])
    assert math.isnan(metrics.rel_l1(img, _img(0.0)))  # no light in the truth: nothing to divide by
    with pytest.raises(ValueError, match="differ"):
        metrics.rel_l1(img[:4], ref)


def test_flip_sees_a_visible_difference_not_an_identical_image():
    pytest.importorskip("flip_evaluator")
    rng = np.random.default_rng(3)
    ref = _img(0.0, 32, 32)
    ref[..., :3] = rng.uniform(0.05, 0.6, (32, 32, 3))
    assert metrics.flip_mean(ref, ref) == 0.0
    slight, strong = ref.copy(), ref.copy()
    slight[..., :3] *= 1.03
    strong[..., :3] *= 1.6
    a, b = metrics.flip_mean(slight, ref), metrics.flip_mean(strong, ref)
    assert 0.0 < a < b <= 1.0
    m = metrics.flip_map(strong, ref)
    assert m.shape == (32, 32) and m.min() >= 0 and m.max() <= 1
    # the tone mapping is the frame's: exposure matters
    assert metrics.flip_mean(strong, ref, exposure=0.01) < b


def test_relative_map_is_full_resolution_and_floored():
    ref = _img((1.0, 1.0, 1.0))
    ref[0, 0, :3] = 0.0  # a black pixel: its difference is measured against the floor, not 0
    img = ref.copy()
    img[1, 1, :3] = 1.2
    img[0, 0, :3] = 0.5
    ref[7, 7, 3] = 0.0
    d = metrics.relative_map(img, ref)
    assert d[1, 1] == pytest.approx(0.2) and d[2, 2] == 0.0 and np.isnan(d[7, 7])
    assert d[0, 0] == pytest.approx(0.5 / 0.01)


def test_jackknife_of_a_mean_is_its_standard_error():
    """For an error linear in the truth the delete-a-group jackknife gives the standard error of the
    mean; two rows measured against the same groups have a paired difference without the shared noise."""
    rng = np.random.default_rng(0)
    groups = rng.normal(1.0, 0.1, 8)
    loo = [(groups.sum() - g) / 7 for g in groups]
    v, s, vals = metrics.jackknife(lambda t: t, groups.mean(), loo)
    assert v == pytest.approx(groups.mean()) and s == pytest.approx(groups.std(ddof=1) / math.sqrt(8))
    assert len(vals) == 8
    assert metrics.jackknife_sigma([0.3, 0.5]) == pytest.approx(0.1)  # two halves: |a - b| / 2
    assert math.isnan(metrics.jackknife_sigma([0.3]))
    a = np.array(vals)
    assert metrics.paired_sigma(a + 0.02, a) == pytest.approx(0.0, abs=1e-12)
    assert metrics.paired_sigma(a, a[:3]) != metrics.paired_sigma(a, a[:3])  # NaN: not the same groups


def test_measure_table_reads_and_names_bad_keys(tmp_path):
    from skinlab.scene.scenefile import SceneFileError, load_scene

    s = load_scene(SLAB_EDGE)
    m = s.measure
    assert m.profile == "edge" and m.profile_axis == (0.0, 1.0, 0.0) and m.profile_origin == (0.0, 24.0, 0.0)
    assert m.tests.startswith("the edge spread function")
    base = SLAB_EDGE.read_text().split("[measure]")[0]
    for table, says in (
        ('profile = "slit"', "[measure].profile: expected one of none, line, edge"),
        ('profile = "line"\nprofile_axis = [0, 1, 0]', "[measure].profile_origin: needed"),
        ('profile = "edge"\nprofile_origin = [0, 0, 0]\nprofile_axis = [0, 0, 0]', "[measure].profile_axis: must be"),
        ("edge_mm = -1", "[measure].edge_mm"),
        ("profile_range_mm = 0", "[measure].profile_range_mm"),
        ("colour = 3", "[measure]: unknown key(s) colour"),
        ('ledger = "no"', "[measure].ledger"),
        ('truth_size = "256by16"', '[measure].truth_size: expected "WxH" or [W, H], integers in [1, 16384], got'),
        ("truth_size = [256, 16.5]", "[measure].truth_size: expected"),
        ('truth_size = "0x16"', "[measure].truth_size: expected"),
        ("truth_size = [1, 2, 3]", "[measure].truth_size: expected"),
        ("truth_spp = 1", "[measure].truth_spp: expected an integer in [2, 16777216], got 1"),
        ("truth_spp = 64.0", "[measure].truth_spp: expected an integer"),
        ("truth_rr_depth = 0", "[measure].truth_rr_depth: expected an integer in [1, 1048576], got 0"),
        ("truth_rr_depth = true", "[measure].truth_rr_depth: expected an integer"),
        ("deep_shadow = 1", "[measure].deep_shadow: expected true or false"),
        ('mesh_energy = "yes"', "[measure].mesh_energy: expected true or false"),
    ):
        p = tmp_path / "s.toml"
        meshes = str(SLAB_EDGE.parent.parent.parent / "meshes")
        p.write_text(base.replace("../../meshes", meshes) + f"[measure]\n{table}\n")
        with pytest.raises(SceneFileError) as exc:
            load_scene(p)
        assert str(exc.value).startswith(str(p)) and says in str(exc.value), str(exc.value)
        assert "\n" not in str(exc.value)
    for table, size in (('truth_size = "256x16"', (256, 16)), ("truth_size = [64, 32]", (64, 32))):
        p.write_text(base.replace("../../meshes", meshes) + f"[measure]\n{table}\ntruth_spp = 8\ntruth_rr_depth = 9\n")
        m = load_scene(p).measure
        assert (m.truth_size, m.truth_spp, m.truth_rr_depth) == (size, 8, 9)


def test_scenes_that_say_ledger_false_are_left_out_of_the_default_list(tmp_path, monkeypatch):
    """A scene whose [measure] says `ledger = false` is left out of the ledger's default scene list; the full
    list keeps it. The seven close-ups (issue 21) are in the default list, each with its own truth's settings."""
    from skinlab.bench import truth_ledger
    from skinlab.bench.sweep import FULL
    from skinlab.bench.truth_ledger import reference_scene_names, scene_truth_spec
    from skinlab.scene.scenefile import load_scene

    closeups = {"slit-skin1", "slit-marble", "nose-shadow-skin1", "ear-backlit-skin1", "point-light-skin1",
                "slabs-gap-backlit-skin1", "ball-backlit-skin1"}  # fmt: skip
    assert closeups | {"head-skin1-matched", "slab-edge-skin1"} <= set(reference_scene_names())
    marble = scene_truth_spec(load_scene("slit-marble"), FULL.truth)
    assert (marble.size, marble.spp, marble.rr_depth, marble.passes) == ((256, 16), 64, 1024, 4)
    assert scene_truth_spec(load_scene("slab-edge-skin1"), FULL.truth) == FULL.truth  # no truth settings of its own
    for name, text in (("a", "[measure]\nledger = false\n"), ("b", "[measure]\nledger = true\n"), ("c", "")):
        (tmp_path / f"{name}.toml").write_text(text)
    monkeypatch.setattr(truth_ledger, "REFERENCE_SCENES", tmp_path)
    assert reference_scene_names() == ["b", "c"] and reference_scene_names(every=True) == ["a", "b", "c"]


def test_pixel_points_see_the_declared_edge_where_the_truth_has_it():
    """Rays through the reference description's camera hit the slab where the camera looks (the shadow
    edge at y = 20 mm across the image's middle row), and the profile across the edge runs from the
    shadow to the light."""
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.export import describe

    s = load_scene(SLAB_EDGE)
    px = regions.pixel_points(describe(s, 24, 16))
    assert px.hit.all() and px.mm_per_pixel == pytest.approx(2 * 300 * math.tan(math.radians(8)) / 16, rel=0.05)
    across, along = regions.across(px, s.measure)
    assert np.all(np.diff(across[:, 12]) < 0)  # the rows run from high y (top) to low y
    assert abs(across[8, 12] + 4.0) < px.mm_per_pixel  # the camera looks at y = 20, 4 mm below the edge
    assert along[8, 12] < px.mm_per_pixel and along[8, 0] > 10 * px.mm_per_pixel
    # a synthetic frame lit above the edge: its profile is a step at 0, the declared edge region a band around it
    img = np.zeros((16, 24, 4), np.float32)
    img[..., 3] = 1.0
    img[..., :3] = (across > 0)[..., None] * 1.0
    prof = regions.profile(img, px, s.measure, img[..., 3] > 0.5)
    ok = prof.count > 0
    assert np.all(prof.rgb[ok & (prof.x_mm < -px.mm_per_pixel), 0] == 0.0)
    assert np.all(prof.rgb[ok & (prof.x_mm > px.mm_per_pixel), 0] == 1.0)
    assert regions.profile_error(prof, prof) == 0.0
    edge = regions.edge_region(img[..., 3] > 0.5, 3.0, px, s.measure)
    assert edge[7].all() and edge.sum() == 24  # the row 1.4 mm above y = 20 (rows are 5.3 mm apart)
    # the default width: 3 diffusion lengths of skin1's most diffuse channel
    assert regions.edge_width_mm(s, s.measure) == pytest.approx(3 * regions.diffusion_length_mm(s))
    assert 1.0 < regions.diffusion_length_mm(s) < 10.0


def test_light_edges_of_the_plain_frame():
    plain = _img(1.0, 16, 16)
    plain[:, 8:, :3] = 0.05  # a shadow on the right half
    plain[:, :3, 3] = 0.0  # background at the left: no edge against it
    plain[:, :3, :3] = 0.0
    m = plain[..., 3] > 0.5
    e = regions.light_edges(plain, m)
    assert e[:, 7].all() and e[:, 8].all() and e.sum() == 32
    grown = regions.edge_region(m, 2.0, None, None, plain)  # 1 mm per pixel without pixel points
    assert grown[:, 5:11].all() and not grown[:, 3:5].any() and not grown[:, 11:].any()


def _write(path, img):
    from skinlab.image_output import write_image

    return write_image(path, img)


def _compare(*args):
    return subprocess.run([sys.executable, "-m", "skinlab.cli", "compare", *map(str, args)], capture_output=True,
                          text=True, timeout=120)  # fmt: skip


def cli_in_process(capsys, *args) -> tuple[int, str, str]:
    """skinlab's main() here (no interpreter start): exit status, stdout, stderr."""
    from skinlab.cli import main

    try:
        code = main([str(a) for a in args])
    except SystemExit as exc:  # argparse's usage errors
        code = exc.code
    got = capsys.readouterr()
    return code, got.out, got.err


def test_compare_command_measures_and_writes_maps(tmp_path):
    pytest.importorskip("flip_evaluator")
    ref = _img((0.2, 0.3, 0.4), 16, 12)
    img = ref.copy()
    img[..., :3] *= 1.1
    a, b = _write(tmp_path / "a.exr", img), _write(tmp_path / "b.exr", ref)
    r = _compare(a, b, "--json", "--out", tmp_path / "maps" / "m.png")
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    assert res["rel_l1"] == pytest.approx(0.1, rel=1e-4) and res["energy"] == pytest.approx([0.1] * 3, rel=1e-4)
    assert res["size"] == [12, 16] and res["pixels"] == 192 and 0 < res["flip_mean"] < 1 and res["linear"]
    from skinlab.image_output import read_image

    assert read_image(tmp_path / "maps" / "m.png").shape[:2] == (16, 12)
    assert read_image(tmp_path / "maps" / "m-flip.png").shape[:2] == (16, 12)
    r = _compare(b, b)
    assert r.returncode == 0 and "relative L1 0.00 %" in r.stdout and "FLIP mean 0.0000" in r.stdout


def test_compare_command_bad_input_is_one_line(tmp_path, capsys):
    ref = _img(0.5, 8, 8)
    b = _write(tmp_path / "b.exr", ref)
    small = _write(tmp_path / "small.exr", ref[:4])
    nan = ref.copy()
    nan[2, 2, 0] = np.nan
    bad = _write(tmp_path / "nan.exr", nan)
    (tmp_path / "junk.exr").write_bytes(b"not an image")
    for args, says in (
        ((tmp_path / "missing.exr", b), "missing.exr: no such file"),
        ((small, b), "small.exr is 8x4, "),
        ((bad, b), "nan.exr: 1 pixel(s) are NaN or Inf"),
        ((tmp_path / "junk.exr", b), "junk.exr: cannot read it as an image"),
        ((b, b, "--out", tmp_path / "m.txt"), "--out"),
        ((b, b, "--exposure", "0"), "--exposure"),
    ):
        code, _, err = cli_in_process(capsys, "compare", *args)
        assert code == 2 and says in err, (args, err)
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
