"""The reference cache checks itself: a whole reference (``<key>.npz`` + ``<key>.json``) or a pass
truncated to half, to 100 bytes, emptied, replaced by garbage, of the wrong shape, full of NaN, or a
record that is ``{}`` or a list is discarded with one warning line and rendered again (the same
image: a series is deterministic); it is never used, never a traceback. A writer killed with SIGKILL
mid-store leaves only dot-named temporaries, which no reader takes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.tsd_scenes import sky_slab

ROOT = Path(__file__).resolve().parents[2]
SIZE = 6


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache" / "reference"


def _npz_bytes(**arrays) -> bytes:
    import io

    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _image(value, size=SIZE):
    return np.full((size, size, 4), value, np.float32)


DAMAGE = {  # what is done to the file's bytes (None: to the record instead)
    "half": lambda good: good[: len(good) // 2],
    "100-bytes": lambda good: good[:100],
    "empty": lambda good: b"",
    "garbage": lambda good: bytes(range(256)) * 8,
    "wrong-shape": lambda good: _npz_bytes(image=_image(1.0, 3), half_a=_image(1.0, 3), half_b=_image(1.0, 3)),
    "all-nan": lambda good: _npz_bytes(image=_image(np.nan), half_a=_image(np.nan), half_b=_image(np.nan)),
}
RECORDS = {"record-empty-table": "{}", "record-a-list": "[1, 2, 3]", "record-garbage": "{not json"}


@pytest.fixture()
def made(cache):
    """A rendered reference filed whole under its key (as tools/gpu_reference.py store does), its
    pass series removed: what is in the cache is the whole entry only."""
    pytest.importorskip("mitsuba")
    import shutil

    from skinlab.truth.export import describe
    from skinlab.truth.reference import ReferenceRequest, reference_key, render_reference, set_variant, store_reference

    scene, req = sky_slab((0.3, 0.5, 0.7)), ReferenceRequest(SIZE, SIZE, spp=4, passes=2)
    ref = render_reference(scene, req, progress=False)
    ref.key = reference_key(describe(scene, SIZE, SIZE), req, set_variant(req.variant).__version__)
    store_reference(ref)
    shutil.rmtree(cache / "passes")
    return scene, req, ref


def _render_again(scene, req, capsys):
    from skinlab.truth.reference import render_reference

    got = render_reference(scene, req, progress=False)
    return got, capsys.readouterr().err


@pytest.mark.parametrize("damage", [*DAMAGE, *RECORDS])
def test_a_damaged_whole_reference_is_discarded_and_rendered_again(made, cache, capsys, damage):
    scene, req, ref = made
    npz, js = cache / f"{ref.key}.npz", cache / f"{ref.key}.json"
    assert npz.is_file() and js.is_file()
    capsys.readouterr()
    if damage in DAMAGE:
        npz.write_bytes(DAMAGE[damage](npz.read_bytes()))
    else:
        js.write_text(RECORDS[damage])
    got, err = _render_again(scene, req, capsys)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: ") and npz.name in lines[0], err
    assert "rendered again" in lines[0] and "Traceback" not in err
    assert not got.cached and got.meta["passes_rendered"] == 2  # rendered, not taken from the damaged entry
    assert np.isfinite(got.image).all() and got.image.shape == (SIZE, SIZE, 4)
    assert np.array_equal(got.image, ref.image)  # the series is deterministic: the same image again
    assert not npz.exists() and not js.exists()  # the damaged entry is gone


def test_a_good_whole_reference_is_used_as_it_is(made, cache, capsys):
    scene, req, ref = made
    capsys.readouterr()
    got, err = _render_again(scene, req, capsys)
    assert err == "" and got.cached and np.array_equal(got.image, ref.image)


@pytest.mark.parametrize("damage", ["half", "100-bytes", "empty", "all-nan"])
def test_a_damaged_pass_is_discarded_and_rendered_again(cache, capsys, damage):
    pytest.importorskip("mitsuba")
    from skinlab.truth.reference import ReferenceRequest, render_reference

    scene, req = sky_slab((0.3, 0.5, 0.7)), ReferenceRequest(SIZE, SIZE, spp=4, passes=2)
    first = render_reference(scene, req, progress=False)
    (series,) = (cache / "passes").iterdir()
    victim = series / "pass-00001.npz"
    victim.write_bytes(DAMAGE[damage](victim.read_bytes()))
    capsys.readouterr()
    again = render_reference(scene, req, progress=False)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pass-00001.npz" in err and "rendered again" in err, err
    assert again.meta["passes_rendered"] == 1 and np.array_equal(again.image, first.image)


def test_the_command_line_says_one_line_and_writes_the_right_image(made, cache, capsys, tmp_path):
    """`skinlab reference` over a damaged entry: exit 0, one warning line, the image of a fresh render."""
    from skinlab.image_output import read_image
    from skinlab.scene.scenefile import load_scene
    from tests.truth.test_metrics import cli_in_process

    scene_file = ROOT / "skinlab" / "assets" / "scenes" / "reference" / "slab-edge-skin1.toml"
    out = tmp_path / "out" / "r.exr"
    args = ("reference", scene_file, "--out", out, "--size", "8x8", "--spp", "4", "--passes", "2", "--json")
    code, stdout, err = cli_in_process(capsys, *args)
    assert code == 0, err
    key = json.loads(stdout)["key"]
    first = read_image(out)
    # file it whole under the key the command looks for, then damage it
    from skinlab.truth.export import describe
    from skinlab.truth.reference import ReferenceRequest, load_cached, reference_key, set_variant, store_reference

    req = ReferenceRequest(8, 8, spp=4, passes=2)
    scene = load_scene(scene_file)
    whole = reference_key(describe(scene, 8, 8), req, set_variant(req.variant).__version__)
    from skinlab.truth.reference import Reference

    store_reference(Reference(first, first, first, whole, {"noise_floor": {}, "seconds": 1.0, "notes": []}))
    assert key and load_cached(whole, (8, 8, 4)) is None  # a record without its noise floor: discarded
    capsys.readouterr()
    store_reference(Reference(_image(np.nan, 8), first, first, whole, {"noise_floor": {}, "seconds": 1.0, "notes": []}))
    code, stdout, err = cli_in_process(capsys, *args)
    assert code == 0 and err.count("\n") == 1 and "discarded a cached reference" in err, err
    assert np.array_equal(read_image(out), first)


KILLED_WRITER = """
import sys, numpy as np
from skinlab.truth.reference import Reference, store_reference
big = np.random.default_rng(0).random((1024, 1024, 4)).astype(np.float32)
meta = {"noise_floor": {"rel_l1": 0.1, "rel_l1_block": 0.05, "pixels": 10}, "seconds": 1.0, "notes": []}
print("ready", flush=True)
i = 0
while True:  # the same key over and over: the parent kills it somewhere inside a store
    store_reference(Reference(big + i, big, big, "k" * 24, meta))
    i += 1
"""


def test_sigkill_mid_store_leaves_nothing_a_reader_takes(cache, tmp_path):
    from skinlab.truth.reference import load_cached

    env = {**os.environ, "SKINLAB_CACHE_DIR": str(cache.parent), "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", KILLED_WRITER], env=env, stdout=subprocess.PIPE)
    assert proc.stdout.readline().strip() == b"ready"
    deadline = time.time() + 60
    while time.time() < deadline and not any(p.name.startswith(".") for p in cache.glob(".*")):
        time.sleep(0.01)  # a temporary exists: a store is under way
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    names = sorted(p.name for p in cache.iterdir())
    assert all(n.startswith(".") or n in ("k" * 24 + ".npz", "k" * 24 + ".json") for n in names), names
    got = load_cached("k" * 24, (1024, 1024, 4))  # the last whole entry, or None; never a half-written one
    assert got is None or (np.isfinite(got.image).all() and got.image.shape == (1024, 1024, 4))
    # the temporaries' names never match a key: a reader asking for any key does not see them
    for n in names:
        if n.startswith("."):
            assert load_cached(Path(n).stem) is None
