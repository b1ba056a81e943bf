"""The `skinlab` command line, run as a user would (in a subprocess)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def skinlab(*args, env=None):
    e = dict(os.environ, **(env or {}))
    return subprocess.run(
        [sys.executable, "-m", "app.cli", *args], cwd=ROOT, capture_output=True, text=True, timeout=300, env=e
    )


def test_render_json_png_and_exr(tmp_path):
    png, exr = tmp_path / "a.png", tmp_path / "b.exr"
    p = skinlab("render", "--out", str(png), "--size", "48x40", "--json", "--explain", "--tsd-size", "256")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["outputs"] == [str(png)] and d["size"] == [48, 40]
    passes = d["timings"]["passes"]
    # the head's skin scatters: texture-space diffusion runs; the timed frame runs every pass
    head = "LeePerrySmith"
    assert {"shadow[key]", f"tsd_stretch[{head}]", f"tsd_irradiance[{head}]", f"tsd_dilate[{head}]"} <= set(passes)
    assert {"forward", "tonemap"} <= set(passes) and any(n.startswith(f"tsd_blur[{head}]") for n in passes)
    assert all(v["cpu_ms"] > 0 for v in passes.values())
    assert all(q["reused_since"] is None for q in d["plan"]["passes"])
    assert "frame plan:" in p.stderr and "tsd_blur" in p.stderr
    # --reuse: the view-independent passes keep the warm-up frame's results
    p = skinlab("render", "--out", str(png), "--size", "48x40", "--json", "--reuse", "--tsd-size", "256")
    d = json.loads(p.stdout)
    assert set(d["timings"]["passes"]) == {"forward", "tonemap"}
    reused = {q["name"]: q["reused_since"] for q in d["plan"]["passes"] if q["reused_since"] is not None}
    assert f"tsd_irradiance[{head}]" in reused and "shadow[key]" in reused and set(reused.values()) == {1}
    assert skinlab("render", "--out", str(exr), "--size", "48x40", "--tsd-size", "256").returncode == 0
    from app.image_output import read_image

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
    assert set(d["timings"]["passes"]) == {"shadow[key]", "forward", "tonemap"}
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

    from app.gl import context

    monkeypatch.setattr(ctypes.util, "find_library", lambda name: None)
    monkeypatch.setattr(context, "_SHARED", None)
    with pytest.raises(context.ContextError, match=r"libEGL.so.1 \(Debian/Ubuntu: apt-get install libegl1"):
        context.create_headless_context()


def test_written_images_have_ordinary_permissions(tmp_path):
    import os
    import stat

    from app.image_output import write_image

    old = os.umask(0o022)
    try:
        p = write_image(tmp_path / "x.png", np.zeros((2, 3, 4), np.uint8))
    finally:
        os.umask(old)
    assert stat.S_IMODE(p.stat().st_mode) == 0o644
