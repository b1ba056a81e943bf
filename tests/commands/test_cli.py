"""The `skinlab` command line, run as a user would (in a subprocess)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def skinlab(*args, env=None):
    e = dict(os.environ, **(env or {}))
    return subprocess.run(
        [sys.executable, "-m", "skinlab.cli", *args], cwd=ROOT, capture_output=True, text=True, timeout=300, env=e
    )


def test_render_json_png_and_exr(tmp_path):
    png, exr = tmp_path / "a.png", tmp_path / "b.exr"
    p = skinlab("render", "--out", str(png), "--size", "48x40", "--json", "--explain", "--tsd-size", "256")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["outputs"] == [str(png)] and d["size"] == [48, 40]
    passes = d["timings"]["passes"]
    # one frame (no --time): its times are the first frame's, compiles and uploads included
    assert d["timed_frame"].startswith("the first frame")
    # the head's skin scatters: texture-space diffusion runs; the frame runs every pass
    head = "LeePerrySmith"
    assert {"shadow[key]", f"tsd_stretch[{head}]", f"tsd_irradiance[{head}]", f"tsd_dilate[{head}]"} <= set(passes)
    assert {"forward", "tonemap"} <= set(passes) and any(n.startswith(f"tsd_blur[{head}]") for n in passes)
    assert all(v["cpu_ms"] > 0 for v in passes.values())
    assert all(q["reused_since"] is None for q in d["plan"]["passes"])
    assert "frame plan:" in p.stderr and "tsd_blur" in p.stderr
    # --reuse: the view-independent passes keep the warm-up frame's results
    p = skinlab("render", "--out", str(png), "--size", "48x40", "--json", "--reuse", "--tsd-size", "256")
    d = json.loads(p.stdout)
    assert d["timed_frame"] == "the second frame, after a warm-up frame"  # --reuse implies --time
    assert set(d["timings"]["passes"]) == {"forward", "tonemap"}
    reused = {q["name"]: q["reused_since"] for q in d["plan"]["passes"] if q["reused_since"] is not None}
    assert f"tsd_irradiance[{head}]" in reused and "shadow[key]" in reused and set(reused.values()) == {1}
    assert skinlab("render", "--out", str(exr), "--size", "48x40", "--tsd-size", "256").returncode == 0
    from skinlab.image_output import read_image

    img = read_image(exr)
    assert img.shape == (40, 48, 4) and img.dtype == np.float32 and np.isfinite(img).all()
    assert img[..., 3].max() == 1.0 and img[..., 3].min() == 0.0
    png_img = read_image(png)
    assert png_img.shape == (40, 48, 4) and png_img.dtype == np.uint8
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def test_render_sss_override(tmp_path):
    """--sss none: no texture-space passes at all; --sss dipole: the chain is planned for the dipole."""
    p = skinlab("render", "--out", str(tmp_path / "n.png"), "--size", "32x32", "--sss", "none", "--json")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert set(d["timings"]["passes"]) == {"shadow[key]", "bounce[1]", "bounce[2]", "forward", "tonemap"}
    assert any("sss_model is none" in s["why"] for s in d["plan"]["skipped"])
    p = skinlab(
        "render",
        "--out",
        str(tmp_path / "d.png"),
        "--size",
        "32x32",
        "--sss",
        "dipole",
        "--explain",
        "--tsd-size",
        "512",
        "--gaussians",
        "3",
    )
    assert p.returncode == 0, p.stderr
    assert "scatters (dipole)" in p.stdout
    p = skinlab("render", "--out", str(tmp_path / "x.png"), "--sss", "fog")
    assert p.returncode == 2 and "invalid choice: 'fog'" in p.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["render", "--out", "x.jpg"], "x.jpg: unsupported image extension '.jpg'; expected .png or .exr"),
        (["render", "missing.toml"], "scene file not found: missing.toml"),
        (["render", "--size", "12"], "--size: expected WIDTHxHEIGHT"),
        (["render", "--size", "8x8", "--tsd-size", "3"], "--tsd-size: expected an integer in [16, 8192], got 3"),
        (["render", "--size", "8x8", "--gaussians", "9"], "--tsd-gaussians: expected an integer in [1, 6], got 9"),
        (["render", "--size", "8x8", "--tsd-taps", "x"], "--tsd-taps: expected an odd integer in [7, 31]"),
        (
            ["render", "--size", "8x8", "--technique", "ssss", "--ssss-taps", "4"],
            "--ssss-taps: expected an odd integer in [3, 63], got 4",
        ),
        (["render", "--size", "8x8", "--ssss-taps", "11"], "--ssss-taps: a setting of technique ssss, but --technique"),
    ],
)
def test_bad_input_is_one_clear_line(args, message):
    p = skinlab(*args)
    assert p.returncode == 2 and message in p.stderr and "Traceback" not in p.stderr


def test_bad_egl_device_is_reported(tmp_path):
    p = skinlab("render", "--out", str(tmp_path / "x.png"), "--size", "8x8", env={"SKINLAB_EGL_DEVICE": "abc"})
    assert p.returncode == 2 and "SKINLAB_EGL_DEVICE must be a device index" in p.stderr


def test_missing_egl_library_names_the_package(monkeypatch):
    import ctypes.util

    from skinlab.gl import context

    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    monkeypatch.setattr(context, "_SHARED", None)
    with pytest.raises(context.ContextError, match=r"libEGL.so.1 \(Debian/Ubuntu: apt-get install libegl1"):
        context.create_headless_context()


def test_written_images_have_ordinary_permissions(tmp_path):
    import os
    import stat

    from skinlab.image_output import write_image

    old = os.umask(0o022)
    try:
        p = write_image(tmp_path / "x.png", np.zeros((2, 3, 4), np.uint8))
    finally:
        os.umask(old)
    assert stat.S_IMODE(p.stat().st_mode) == 0o644


def test_exr_keeps_radiance_above_the_half_float_range(tmp_path):
    """A light of intensity 1e6 gives radiance above 65504: the EXR must hold it, not +Inf."""
    from skinlab.image_output import read_image, write_image

    px = np.zeros((2, 3, 4), np.float32)
    px[0, 0, :3] = [1e6, 7e4, 0.125]
    px[..., 3] = 1
    back = read_image(write_image(tmp_path / "x.exr", px))
    assert back.dtype == np.float32 and np.isfinite(back).all()
    assert np.array_equal(back, px)


def test_render_a_mesh_file_with_camera_orbit_and_exposure(tmp_path):
    obj = tmp_path / "quad.obj"
    obj.write_text("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n")
    outs = {}
    for name, extra in (("a", []), ("b", ["--exposure", "3", "--camera-orbit", "30"])):
        out = tmp_path / f"{name}.exr"
        p = skinlab("render", str(obj), "--out", str(out), "--size", "32x32", *extra)
        assert p.returncode == 0, p.stderr
        assert "warning:" not in p.stderr  # a plain quad: nothing to warn about
        assert "frame (total)" in p.stdout and "forward" in p.stdout
        from skinlab.image_output import read_image

        outs[name] = read_image(out)
    a, b = outs["a"], outs["b"]
    assert 0.05 < a[..., 3].mean() < 0.95  # the default camera frames the quad
    assert 0.02 < b[..., 3].mean() < a[..., 3].mean() - 0.02  # seen 30 degrees off its normal: narrower


def test_gallery_contact_sheet_tiles_and_labels():
    from skinlab.image_output import contact_sheet

    tiles = [(np.full((10, 12, 4), 40 * i, np.uint8), f"t{i}") for i in range(5)]
    tiles[0][0][..., 3] = 0  # a tile's alpha does not make the sheet transparent
    label = 16
    sheet = contact_sheet(tiles, columns=3, label_px=label)
    assert sheet.shape == (2 * (10 + label), 3 * 12, 4) and sheet.dtype == np.uint8
    assert (sheet[..., 3] == 255).all()
    for i in range(5):
        x, y = (i % 3) * 12, (i // 3) * (10 + label)
        assert (sheet[y : y + 10, x : x + 12, :3] == 40 * i).all()
    strip = sheet[10 : 10 + label, 0:12, :3]
    assert strip.max() > 150  # the label is drawn in the strip below its tile
    assert (sheet[10 + label : 20 + label, 24:, :3] == (20, 20, 22)).all()  # the empty sixth cell is background
    import pytest

    with pytest.raises(ValueError, match="tile 'x' is 5x5, expected 12x10"):
        contact_sheet([tiles[0], (np.zeros((5, 5, 4), np.uint8), "x")])


def test_timing_table_is_aligned_with_a_total():
    from skinlab.render.timing import FrameTimings, PassTime

    t = FrameTimings([PassTime("shadow[key]", 1.5, 2.0), PassTime("tsd_irradiance[LeePerrySmith]", None, 10.25)])
    lines = t.table().splitlines()
    assert "GPU timer queries" in lines[0]
    body = lines[1:]
    assert len({len(l) for l in body}) == 1  # every row the same width: aligned columns
    assert body[-1].split()[-2:] == ["12.25", "n/a"]  # cpu total; no gpu total when a pass has none
    assert "frame (total)" in body[-1]
    t2 = FrameTimings([PassTime("a", 1.0, 2.0), PassTime("b", 3.0, 4.0)], software_gl=True)
    assert t2.table().splitlines()[-1].split()[-2:] == ["6.00", "4.00"]
    assert "CPU, synchronised" in t2.table()


def test_bench_peer_shows_progress(monkeypatch, capsys):
    """bench peer reports its frames on a progress bar (pyrender's side stubbed: it has its own test)."""
    from skinlab.bench import pyrender_peer
    from skinlab.bench.peer import peer_bench

    calls = []

    class FakePeer:
        def __init__(self, meshes, pose, yfov, znear, zfar, size, timeout=600):
            pass

        def time_frames(self, n):
            calls.append(n)
            return [1.0] * n

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            pass

    monkeypatch.setattr(pyrender_peer, "PeerSession", FakePeer)
    res = peer_bench((16, 16), frames=2, progress=True, rounds=2)
    err = capsys.readouterr().err
    assert calls == [1, 1] and res["pyrender_ms"] == 1.0 and len(res["ratio_per_round"]) == 2
    assert "bench peer" in err and "14/14" in err  # 3 x 2 warm-up + 2 rounds x (3 Skinlab + 1 pyrender)
    peer_bench((16, 16), frames=1, progress=False)
    assert "bench peer" not in capsys.readouterr().err


@pytest.mark.slow
def test_demo_gallery_writes_images_markdown_and_contact_sheet(tmp_path, capsys):
    from skinlab.cli import main
    from skinlab.image_output import read_image

    assert main(["demo", "--out", str(tmp_path), "--size", "24x24", "--gallery"]) == 0
    out, err = capsys.readouterr()
    g = tmp_path / "gallery"
    pngs = sorted(p.name for p in g.glob("*.png"))
    assert len(pngs) == 10 and "gallery.png" in pngs and "head-burley.png" in pngs and "bunny-ketchup.png" in pngs
    sheet = read_image(g / "gallery.png")
    assert sheet.shape == (3 * (24 + 18), 3 * 24, 4)
    md = (g / "gallery.md").read_text()
    assert "![contact sheet](gallery.png)" in md and md.count("| ![") == 9
    assert "gallery: 100%" in err and "9/9" in err  # the progress bar
    assert "frame (total)" in out and str((g / "gallery.png").resolve()) in out
    assert not [p for p in tmp_path.rglob(".*")]  # nothing half-written
