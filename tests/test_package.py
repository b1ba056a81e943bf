"""Skinlab as an installed package: a wheel built from the checkout, installed (not editable) into a
fresh virtual environment, used from a directory outside the checkout; and nothing heavy at import."""

from __future__ import annotations

import os
import site
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(cmd, cwd, **kw):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=600, **kw)
    assert r.returncode == 0, (cmd, r.stdout[-2000:], r.stderr[-2000:])
    return r


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(python, skinlab, wheel) of a new environment with the wheel installed; its dependencies are
    this environment's (a .pth line, so that the test needs no download), skinlab itself is the wheel's."""
    tmp = tmp_path_factory.mktemp("wheel")
    run(
        [sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "--no-build-isolation", "-q", "-w", str(tmp)],
        tmp,
    )
    (wheel,) = tmp.glob("skinlab-*.whl")
    env = tmp / "env"
    run([sys.executable, "-m", "venv", "--without-pip", str(env)], tmp)
    py = env / "bin" / "python"
    purelib = run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], tmp).stdout.strip()
    deps = [p for p in site.getsitepackages() if Path(p).is_dir()]
    (Path(purelib) / "skinlab_test_deps.pth").write_text("\n".join(deps) + "\n")
    run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "--no-index", "-q", str(wheel)], tmp)
    return py, env / "bin" / "skinlab", wheel


def test_the_wheel_ships_shaders_and_assets(installed):
    names = zipfile.ZipFile(installed[2]).namelist()
    for needed in (
        "skinlab/shaders/passes/forward.frag",
        "skinlab/shaders/lib/brdf.glsl",
        "skinlab/assets/scenes/head.toml",
        "skinlab/assets/scenes/reference/slab-edge-skin1.toml",
        "skinlab/assets/lee-perry-smith/LeePerrySmith.glb",
        "skinlab/assets/presets/jensen2001_table1.csv",
        "skinlab/assets/ATTRIBUTION.md",
    ):
        assert needed in names, needed
    assert not any(n.startswith(("tests/", "tools/", "docs/")) for n in names)


@pytest.mark.slow
def test_the_installed_package_renders_from_another_directory(installed, tmp_path):
    py, skinlab, _ = installed
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = dict(os.environ, PYTHONPATH="")  # nothing of the checkout on the path
    code = (
        "import skinlab, pathlib; print(pathlib.Path(skinlab.__file__).resolve()); print(skinlab.__version__); "
        "f = skinlab.render(skinlab.load('head'), 24, 16, technique='tsd', size=64); print(f.ldr.shape)"
    )
    out = run([str(py), "-c", code], elsewhere, env=env).stdout.split("\n")
    assert not Path(out[0]).is_relative_to(ROOT), out[0]  # the wheel's copy, not the checkout's
    assert out[2] == "(16, 24, 4)"
    version = out[1]
    assert run([str(skinlab), "--version"], elsewhere, env=env).stdout.strip() == f"skinlab {version}"
    listed = run([str(skinlab), "scenes"], elsewhere, env=env).stdout
    assert any(line.split()[0] == "bunny-marble" for line in listed.splitlines())
    run([str(skinlab), "render", "--out", "x.png", "--size", "24x24", "--tsd-size", "64"], elsewhere, env=env)
    run(
        [str(skinlab), "render", "bunny-marble", "--out", "b.exr", "--size", "16x16", "--tsd-size", "64"],
        elsewhere,
        env=env,
    )
    assert (elsewhere / "x.png").stat().st_size > 0 and (elsewhere / "b.exr").stat().st_size > 0
    r = subprocess.run(
        [str(skinlab), "render", "bunny", "--out", "y.png"], cwd=elsewhere, env=env, capture_output=True, text=True
    )
    assert r.returncode == 2 and "no bundled scene of that name" in r.stderr and "bunny-marble" in r.stderr


def test_importing_the_package_and_every_command_builds_no_table():
    """No profile, quadrature or lookup table is computed at import time (skinlab/cache.py counts
    every table and stored result as it is made; the raw builders are counted too, in case one is
    called outside a table), and building the command line computes none either."""
    code = """
import importlib, pkgutil
import numpy.polynomial.legendre as leg
calls = []
leggauss = leg.leggauss
leg.leggauss = lambda *a: calls.append("leggauss") or leggauss(*a)
from skinlab.scene.optics import pbd
pbd_ms = pbd.pbd_ms_profile
pbd.pbd_ms_profile = lambda *a, **k: calls.append("pbd") or pbd_ms(*a, **k)
import skinlab, skinlab.cli
for m in pkgutil.walk_packages(skinlab.__path__, "skinlab."):
    importlib.import_module(m.name)
skinlab.cli.build_parser()
from skinlab.render import registry
registry.techniques()
from skinlab.cache import BUILT, LOADED
print(dict(BUILT), dict(LOADED), calls)
"""
    r = run([sys.executable, "-c", code], ROOT)
    assert r.stdout.strip() == "{} {} []", r.stdout
