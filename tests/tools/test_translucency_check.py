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
    for name in translucency_check.MODELS:
        line = next(x for x in out.splitlines() if x.split()[:1] == [name])
        errs = [float(x) for x in line.split("model")[1].split("(")[0].split()]
        scales = [float(x) for x in line.split("(times")[1].split("to the")[0].split()]
        assert len(errs) == 3 and max(errs) < 0.15, line  # the frame's own pattern (its edges aside)
        # and its level: the tool shades as the renderer (on a flat slab the entry face's cosine is the
        # front's); normal-flux leaves out the far face's cosine, 0.866 here (issue 21's measure)
        level = 0.866 if name == "normal-flux" else 1.0
        assert np.allclose(scales, level, atol=0.02), line
    assert (tmp_path / "maps" / "chord.png").is_file()


def test_the_composite_of_the_renderers_model_is_near_the_frame(tmp_path, capsys, renderer):
    """--composite: the frame without translucency plus the chord model's light through is near the
    frame with it (on the flat slab; not equal: no diffusion of the light through, ray-cast chords)."""
    scene_file = REFERENCE_SCENES / "slab-thin-backlit-skin1.toml"
    st = RenderSettings.for_technique("tsd", 24, 24, supersample=4)
    frame = write_image(tmp_path / "frame.exr", renderer.render(load_scene(scene_file), st, readback=("hdr",)).hdr)
    assert translucency_check.main([str(scene_file), str(frame), str(frame), "--composite", "tsd"]) == 0
    rows = {}
    for x in capsys.readouterr().out.splitlines():
        if " 4x4 " in x:
            rows[x.split(" 4x4 ")[0].strip()] = float(x.split(" 4x4 ")[1].split("%")[0])
    assert rows["tsd (its translucency)"] < 0.5  # the truth here is the same frame
    assert rows["tsd without translucency"] > 90  # nearly all the light came through
    assert rows["+ chord"] < 6 and rows["+ entry"] < 6, rows


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
