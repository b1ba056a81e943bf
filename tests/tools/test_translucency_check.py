"""tools/translucency_check.py at a tiny size: on the flat back-lit slab, where the renderer's local slab
is exact, both models' predictions are the frame's shading, at its level (scale 1) and pattern."""

import numpy as np

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.image_output import write_image
from skinlab.render.settings import RenderSettings
from skinlab.scene.scenefile import load_scene
from tools import translucency_check


def test_on_a_flat_slab_the_chord_model_is_the_frames(tmp_path, capsys, renderer):
    scene_file = REFERENCE_SCENES / "slab-thin-backlit-skin1.toml"
    st = RenderSettings(24, 24, shadow_size=256)  # the default technique: light through the slab
    img = renderer.render(load_scene(scene_file), st, readback=("hdr",)).hdr
    frame = write_image(tmp_path / "frame.exr", img)
    assert translucency_check.main([str(scene_file), str(frame), str(frame), "--out", str(tmp_path / "maps")]) == 0
    out = capsys.readouterr().out
    assert img[..., :3].max() > 0.01  # light came through
    for name in ("chord", "normal"):
        line = next(x for x in out.splitlines() if x.strip().startswith(name))
        errs = [float(x) for x in line.split("model")[1].split("(")[0].split()]
        scales = [float(x) for x in line.split("(times")[1].split("to the")[0].split()]
        assert len(errs) == 3 and max(errs) < 0.15, line  # the frame's own pattern (its edges aside)
        assert np.allclose(scales, 1.0, atol=0.02), line  # and its level: the tool shades as the renderer
    assert (tmp_path / "maps" / "chord.png").is_file()


def test_a_frame_of_another_size_is_refused(tmp_path):
    a = write_image(tmp_path / "a.exr", np.zeros((4, 4, 4), np.float32))
    b = write_image(tmp_path / "b.exr", np.zeros((8, 8, 4), np.float32))
    scene_file = str(REFERENCE_SCENES / "slab-thin-backlit-skin1.toml")
    try:
        translucency_check.main([scene_file, str(a), str(b)])
    except SystemExit as exc:
        assert "render them at one size" in str(exc)
    else:
        raise AssertionError("a size mismatch was accepted")
