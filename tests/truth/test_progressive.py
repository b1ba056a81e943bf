"""Progressive, resumable references: passes saved one file each as they finish, validated on load,
added up across runs; --until-noise and --time; what a reference took recorded with it."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from skinlab.truth.passes import Pass, PassSet, PassStore, split_by_samples
from tests.truth.test_truth_render import sky_slab

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))


def _series_dir(tmp_path) -> Path:
    (d,) = (tmp_path / "cache" / "reference" / "passes").iterdir()
    return d


def test_split_by_samples_and_weighted_halves():
    assert [list(g) for g in split_by_samples([4, 4, 4, 4], 2)] == [[0, 1], [2, 3]]
    assert [list(g) for g in split_by_samples([8, 2, 2, 2, 2], 2)] == [[0], [1, 2, 3, 4]]
    groups = split_by_samples([1] * 10, 8)
    assert len(groups) == 8 and sorted(np.concatenate(groups)) == list(range(10))
    assert [list(g) for g in split_by_samples([5], 8)] == [[0]]
    imgs = np.stack([np.full((2, 2, 4), v, np.float32) for v in (1.0, 3.0, 5.0)])
    ps = PassSet(imgs, np.array([2, 1, 1]))
    assert ps.mean()[0, 0, 0] == pytest.approx((2 + 3 + 5) / 4)  # weighted by samples
    a, b = ps.halves()
    assert a[0, 0, 0] == pytest.approx(1.0) and b[0, 0, 0] == pytest.approx(4.0)
    loo = ps.jackknife_groups(8)
    assert len(loo) == 3 and loo[0][0, 0, 0] == pytest.approx(4.0)


def test_store_ignores_temporary_files_and_discards_damaged_passes(tmp_path, capsys):
    store = PassStore(tmp_path / "s", (2, 3, 4))
    good = Pass(0, np.ones((2, 3, 4), np.float32), 8, 0.5)
    store.save(good)
    (tmp_path / "s" / ".pass-00001.abc.npz").write_bytes(b"half written")  # a killed writer's temporary
    (tmp_path / "s" / "pass-00002.npz").write_bytes(b"garbage")
    np.savez(tmp_path / "s" / "pass-00003.npz", image=np.ones((4, 4, 4), np.float32), spp=8, seconds=0.1)
    bad = np.ones((2, 3, 4), np.float32)
    bad[0, 0, 0] = np.nan
    np.savez(tmp_path / "s" / "pass-00004.npz", image=bad, spp=8, seconds=0.1)
    got = store.load()
    assert [p.index for p in got] == [0] and np.array_equal(got[0].image, good.image) and got[0].spp == 8
    err = capsys.readouterr().err
    assert err.count("warning:") == 3 and "pass-00002.npz" in err and "rendered again" in err
    assert sorted(p.name for p in (tmp_path / "s").iterdir()) == [".pass-00001.abc.npz", "pass-00000.npz"]


def test_passes_add_up_across_runs_and_stop_at_the_noise_asked(tmp_path):
    pytest.importorskip("mitsuba")
    from skinlab.truth.reference import ReferenceRequest, render_reference

    s = sky_slab((0.3, 0.5, 0.7))
    req = ReferenceRequest(6, 6, spp=4, passes=2)
    first = render_reference(s, req, progress=False)
    assert not first.cached and first.meta["passes"] == 2 and first.meta["spp"] == 4
    assert first.meta["passes_rendered"] == 2 and first.meta["seconds"] > 0
    assert first.pass_set.count == 2
    # a quieter one: passes are added to the cached two until the block noise is under 3 %
    quiet = render_reference(s, req, progress=False, until_noise=0.03)
    assert quiet.noise["rel_l1_block"] <= 0.03 and quiet.meta["passes"] > 2 and quiet.meta["passes"] % 2 == 0
    assert quiet.meta["passes_rendered"] == quiet.meta["passes"] - 2
    assert np.array_equal(quiet.pass_set.images[0], first.pass_set.images[0])  # the first passes kept
    # asked again, every cached pass is used and nothing rendered
    again = render_reference(s, req, progress=False)
    assert again.cached and again.meta["passes"] == quiet.meta["passes"] and np.array_equal(again.image, quiet.image)
    # --time: passes for about that long
    t0 = time.perf_counter()
    timed = render_reference(s, req, progress=False, time_s=0.5)
    assert timed.meta["passes_rendered"] >= 1 and time.perf_counter() - t0 < 30
    # without rendering: what the cache holds, or None for a series it has no passes of
    assert render_reference(s, req, progress=False, render=False).meta["passes"] == timed.meta["passes"]
    other = ReferenceRequest(6, 6, spp=4, passes=2, seed=5)
    assert render_reference(s, other, progress=False, render=False) is None
    info = json.loads((_series_dir(tmp_path) / "series.json").read_text())
    assert info["passes"] == timed.meta["passes"] and info["spp"] == timed.meta["spp"]


def test_bad_progressive_options_are_one_line(tmp_path, capsys):
    from tests.truth.test_metrics import cli_in_process

    for args, says in (
        (["--until-noise", "0"], "--until-noise"),
        (["--until-noise", "lots"], "--until-noise"),
        (["--time", "-3"], "--time"),
    ):
        code, _, err = cli_in_process(capsys, "reference", "--out", tmp_path / "x.exr", *args)
        assert code == 2 and says in err and len(err.strip().splitlines()) == 1, err
        assert not (tmp_path / "x.exr").exists()


def test_a_killed_reference_resumes_from_its_saved_passes(tmp_path):
    """SIGKILL while the passes render: the passes saved so far are whole, no temporary is taken for
    one, and the next run renders only the rest."""
    pytest.importorskip("mitsuba")
    scene = ROOT / "skinlab" / "assets" / "scenes" / "reference" / "slab-edge-skin1.toml"
    out = tmp_path / "ref.exr"
    cmd = [sys.executable, "-m", "skinlab.cli", "reference", str(scene), "--out", str(out), "--size", "16x16",
           "--spp", "384", "--passes", "24", "--json"]  # fmt: skip
    env = {**os.environ, "SKINLAB_CACHE_DIR": str(tmp_path / "cache")}
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    passes = tmp_path / "cache" / "reference" / "passes"
    deadline = time.time() + 120
    while time.time() < deadline:
        done = list(passes.glob("*/pass-*.npz")) if passes.is_dir() else []
        if len(done) >= 3:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    saved = len(list(passes.glob("*/pass-*.npz")))
    assert 3 <= saved < 24 and not out.exists()
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    assert res["passes"] == 24 and res["passes_rendered"] == 24 - saved and res["spp"] == 384
    assert res["render_seconds"] > 0 and res["noise_floor"]["pixels"] > 0
    assert res["pixel_standard_error"]["median"] > 0
    assert out.is_file() and out.with_name("ref-noise.png").is_file()
