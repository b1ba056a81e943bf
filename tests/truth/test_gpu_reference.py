"""References rendered elsewhere (tools/gpu_reference.py): a scene's description saved and loaded with
nothing but numpy (skinlab/truth/description.py), rendered from the saved file, filed in the cache under
its request's key, and preferred by the ledger where a quieter one is cached (QUIET_REFERENCES)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from skinlab.bench import truth_ledger
from skinlab.bench.truth_ledger import TruthSpec, load_truth
from skinlab.truth.description import load, save
from skinlab.truth.export import describe
from skinlab.truth.reference import ReferenceRequest, reference_key
from tests.truth.test_truth_export import _box_scene

ROOT = Path(__file__).resolve().parents[2]


def test_a_saved_description_loads_with_the_same_content_and_key(tmp_path):
    d = describe(_box_scene(), 12, 8)
    save(d, tmp_path / "d.npz")
    e = load(tmp_path / "d.npz")
    same = lambda x: json.dumps(x.content(), sort_keys=True, default=float)  # noqa: E731
    assert same(e) == same(d)
    assert all(np.array_equal(a, b) for a, b in zip(e.arrays(), d.arrays()))
    req = ReferenceRequest(12, 8, spp=8, passes=2)
    assert reference_key(e, req, "3.9.1") == reference_key(d, req, "3.9.1")


def test_rendered_elsewhere_stored_and_preferred_by_the_ledger(tmp_path, monkeypatch):
    pytest.importorskip("mitsuba")
    monkeypatch.setenv("SKINLAB_CACHE_DIR", str(tmp_path / "cache"))
    scene = _box_scene()
    scene.source = tmp_path / "quiet-box.toml"  # the ledger finds a scene's quiet references by its file's stem
    desc_path = tmp_path / "box.npz"
    save(describe(scene, 8, 8), desc_path)
    tool = [sys.executable, "-m", "tools.gpu_reference"]  # from the repository root (cwd)
    res = tmp_path / "res.npz"
    run = subprocess.run(
        [*tool, "render", str(desc_path), "--spp", "8", "--passes", "2", "--variant", "scalar_rgb", "--seed", "3",
         "--chunk", "4", "--out", str(res)],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    with np.load(res) as z:
        assert z["image"].shape == (8, 8, 4) and np.isfinite(z["image"]).all() and z["image"][..., 3].max() == 1.0
    # filing needs the scene itself: store's part, done here in-process (the tool loads a scene file)
    from skinlab.truth.compare import image_error, object_mask
    from skinlab.truth.reference import Reference, store_reference

    with np.load(res) as z:
        image, a, b = z["image"], z["half_a"], z["half_b"]
        meta = json.loads(bytes(z["meta"]).decode())
    quiet = TruthSpec((8, 8), 8, passes=2, variant=meta["variant"], seed=3)
    key = reference_key(describe(scene, 8, 8), quiet.request(), meta["mitsuba"])
    store_reference(Reference(image, a, b, key, {**meta, "noise_floor": image_error(a, b, object_mask(image))}, False))
    assert load_truth(scene, quiet) is not None
    plain = TruthSpec((8, 8), 256, passes=2)
    assert load_truth(scene, plain) is None  # nothing of this request cached, no quiet one known
    monkeypatch.setitem(truth_ledger.QUIET_REFERENCES, "quiet-box", (quiet,))
    got = load_truth(scene, plain)
    assert got is not None and np.array_equal(got.image, image) and got.meta["seed"] == 3
    assert load_truth(scene, plain, quiet=False) is None
    assert load_truth(scene, TruthSpec((16, 16), 256, passes=2)) is None  # only a reference of the asked size
