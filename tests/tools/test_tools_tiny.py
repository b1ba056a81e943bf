"""Every tool in tools/ runs from the package (``tools.NAME.main(argv)``) at a tiny size, with its
argparse options, and reports what it says it does. The larger tools have modules of their own here
(truth_table, closeup_table, the cost tools); gpu_reference is run by tests/truth/test_gpu_reference.py."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

import tools
from skinlab.resources import asset_path

TOOLS = Path(tools.__file__).parent
TESTED_ELSEWHERE = {
    "truth_table", "closeup_table", "forward_cost", "irradiance_cost", "orbit_cost", "cost_variants", "gpu_reference",
    "closeup_variants",
}  # fmt: skip
HERE = {
    "accuracy_table", "boundary_slab", "branch_cost", "env_sphere", "frame_times", "full_over_plain",
    "make_face_parts", "make_reference_meshes", "near_light_check", "repair_bunny", "seam_report",
    "slab_gap", "supersample_cost", "translucency_check",
}  # fmt: skip


def test_every_tool_is_tested_says_what_it_is_and_takes_options():
    names = {p.stem for p in TOOLS.glob("*.py")} - {"__init__"}
    assert names == TESTED_ELSEWHERE | HERE, names ^ (TESTED_ELSEWHERE | HERE)
    for name in sorted(names):
        text = (TOOLS / f"{name}.py").read_text(encoding="utf-8")
        assert "not a feature" in text.split("\n\n")[0], name  # a one-off analysis, maintenance, ...
        assert "os.environ" not in text and "sys.argv" not in text, name  # options, not variables or argv by hand
        assert "from tests" not in text and "import tests" not in text, name


def test_accuracy_table(tmp_path):
    from tools import accuracy_table

    out = tmp_path / "table.md"
    assert accuracy_table.main(["--photons", "2000", "--no-progress", "--out", str(out)]) == 0
    rows = [line for line in out.read_text().splitlines() if re.match(r"\| 0\.\d+ \|", line)]
    assert len(rows) == 2 * len(accuracy_table.ALBEDOS)  # the total and the shape table
    assert [line.count("|") for line in rows] == [len(accuracy_table.MODELS) + 3] * len(accuracy_table.ALBEDOS) + [
        len(accuracy_table.MODELS) + 2
    ] * len(accuracy_table.ALBEDOS)  # albedo, MC total, models; albedo, models


def test_boundary_slab(capsys):
    pytest.importorskip("mitsuba")
    from tools import boundary_slab

    assert boundary_slab.main(["--spp", "4", "--angles", "0"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("head-skin1: eta 1.300")
    assert [line.split(":")[0] for line in out[1:]] == [
        "rough 0.45 medium sky view  0", "rough 0.45 medium sun light  0",
        "rough 0.45 dark   sky view  0", "rough 0.45 dark   sun light  0",
    ]  # fmt: skip
    assert "model" in out[1] and "model" not in out[3]  # the boundary model for the medium under the sky only


def test_branch_cost(capsys):
    from tools import branch_cost

    assert branch_cost.main(["--size", "64", "--rounds", "1", "--stripe", "4"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].endswith("64x64 (looped branch)") and [line.split()[0] for line in out[1:]] == [
        "not",
        "taken",
        "stripes",
    ]
    assert all(float(line.split()[-2]) >= 0.0 for line in out[1:])
    from tools.branch_cost import FRAGMENT, STRAIGHT

    assert "for (" in FRAGMENT and "for (" not in STRAIGHT and STRAIGHT.count("texelFetch") == 65  # written out
    assert branch_cost.main(["--size", "64", "--rounds", "1", "--straight"]) == 0
    assert capsys.readouterr().out.splitlines()[0].endswith("(straight-line branch)")


def test_env_sphere(tmp_path, capsys):
    from skinlab.scene.scenefile import load_scene
    from tools import env_sphere

    assert env_sphere.main(["scenes", str(tmp_path)]) == 0
    for name in ("sphere-white", "sphere-studio-rest"):
        scene = load_scene(tmp_path / f"{name}.toml")
        lo, hi = scene.world_bounds()
        assert np.allclose(hi - lo, 2 * env_sphere.RADIUS_MM, rtol=1e-3)  # the sphere, whole
    capsys.readouterr()
    assert env_sphere.main(["mc", "--radii", "5,1000", "--photons", "4000"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert len(out) == 3 and all(line.startswith("albedo") for line in out)
    gains = [[float(x) for x in re.findall(r"l: ([+-][0-9.]+)", line)] for line in out]
    assert all(small > large for small, large in gains)  # a small sphere reflects more than a large one


def test_frame_times(tmp_path, capsys):
    from tools import frame_times

    out = tmp_path / "times.json"
    argv = ["--size", "16x16", "--frames", "1", "--warmup-s", "0", "--scenes", "head", "--techniques", "none"]
    assert frame_times.main([*argv, "--compute", "off", "--out", str(out)]) == 0
    d = json.loads(out.read_text())
    assert d["size"] == [16, 16] and len(d["results"]) == 4  # none with and without interreflection, full / reuse
    assert {r["reuse"] for r in d["results"]} == {True, False} and all(r["frame_ms"] > 0 for r in d["results"])


def test_full_over_plain(capsys):
    from tools import full_over_plain

    assert full_over_plain.main(["--frames", "1", "--size", "16", "--scenes", "head"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["size"] == 16 and set(d["head"]["cpu_ms"]) == {"full", "plain", "orbit"}
    assert d["head"]["full_over_plain_cpu"] == pytest.approx(d["head"]["cpu_ms"]["full"] / d["head"]["cpu_ms"]["plain"])
    assert "tsd_irradiance[LeePerrySmith]" in d["head"]["passes_cpu_ms"]["full"]


def test_slab_gap(capsys):
    """The gap's round trips: all kept reads the summed slab, fewer kept pass less, red (the highest
    albedo, the most reflected) loses most; the view factor's closed form; the Monte Carlo near the
    slab model (a tiny photon count, a loose bound). The frame against the truth needs a cached truth."""
    from tools import slab_gap

    assert slab_gap.main(["--gap"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("two 3 mm slabs") and lines[1].startswith("  F = 1.00: 1.000 / 1.000 / 1.000")
    kept = [[float(x) for x in line.split(":")[1].split("(")[0].split("/")] for line in lines[1:]]
    assert all(a > b for a, b in zip(kept[1][0:1] + kept[2][0:1], kept[2][0:1] + kept[3][0:1]))
    assert all(row[0] < row[1] < row[2] <= 1.0 for row in kept[1:])
    assert slab_gap.parallel_squares_view_factor(1.0, 1.0) == pytest.approx(0.1998, abs=1e-4)
    assert 0.7 < slab_gap.parallel_squares_view_factor(60.0, 10.0) < 0.75
    flux, _ = slab_gap.monte_carlo(0.9, 1.0, 2.0, 1.0, 20_000, seed=1)
    from skinlab.scene.optics.slab import slab_table, slab_through

    model = slab_through(1.0, 2.0, slab_table([0.9] * 3, [1.0] * 3), [1.0] * 3, [0.9] * 3, 1.0)[0]
    assert flux == pytest.approx(model, rel=0.05)


def test_supersample_cost(capsys):
    from tools import supersample_cost

    assert supersample_cost.main(["--rounds", "1", "--frames", "1", "--size", "16"]) == 0
    out = capsys.readouterr().out
    assert [line.split(":")[0] for line in out.splitlines()[:3]] == ["N=1", "N=2", "N=4"]
    assert "(x1.00 of N=1)" in out


def test_seam_report(capsys):
    from tools import seam_report

    assert seam_report.main(["--scenes", "slab-thin-backlit-skin1", "--size", "16", "--rounds", "1"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("slab-thin-backlit-skin1: 12 triangles") and "gutter" in out and "seams on vs off" in out


def test_make_reference_meshes_writes_the_shipped_meshes(tmp_path):
    from tools import make_reference_meshes

    assert make_reference_meshes.main(["--out", str(tmp_path)]) == 0
    for name in make_reference_meshes.MESHES:
        made = (tmp_path / name).read_text().splitlines()
        shipped = asset_path("meshes", name).read_text().splitlines()
        assert made[1:] == shipped[1:], name  # (the first line names the writer)


def test_make_face_parts_writes_the_shipped_parts(tmp_path):
    from tools import make_face_parts

    assert make_face_parts.main(["--out", str(tmp_path)]) == 0
    for name in ("face-parts.glb", "iris.png", "lashes.png"):
        assert (tmp_path / name).read_bytes() == asset_path("face-parts", name).read_bytes(), name


def test_repair_bunny_closes_an_open_mesh(tmp_path, capsys):
    from skinlab.scene.mesh_topology import edge_report
    from tools import repair_bunny

    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], np.float64)  # index 4x + 2y + z
    quads = [(0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4)]  # x 0, x 1, y 0, y 1, z 0
    faces = []
    for a, b, c, d in quads:  # two triangles each, wound outward; the z = 1 side left open (a hole)
        for tri in ((a, b, c), (a, c, d)):
            n = np.cross(cube[tri[1]] - cube[tri[0]], cube[tri[2]] - cube[tri[0]])
            faces.append(tri if n @ (cube[list(tri)].mean(0) - 0.5) > 0 else tri[::-1])
    open_box = tmp_path / "open.ply"
    open_box.write_text(repair_bunny.ply_text(cube, np.array(faces)))
    out = tmp_path / "closed.ply"
    assert repair_bunny.main(["--source", str(open_box), "--out", str(out)]) == 0
    assert "watertight True, winding consistent True" in capsys.readouterr().out
    from skinlab.scene.loaders import load_mesh_file

    mesh = load_mesh_file(out)[0].mesh
    assert mesh is not None and edge_report(mesh).closed and np.isfinite(mesh.positions).all()


def test_translucency_check(tmp_path, capsys):
    pytest.importorskip("mitsuba")
    from skinlab.bench.truth_ledger import REFERENCE_SCENES
    from skinlab.gl.context import create_headless_context
    from skinlab.image_output import write_image
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.reference import ReferenceRequest, render_reference
    from tools import translucency_check

    path = REFERENCE_SCENES / "slab-thin-backlit-skin1.toml"
    scene = load_scene(path)
    truth = render_reference(scene, ReferenceRequest(8, 8, spp=4, passes=2), progress=False)
    r = Renderer(create_headless_context())
    frame = r.render(scene, RenderSettings(8, 8), readback=("hdr",)).hdr
    r.release()
    write_image(tmp_path / "truth.exr", truth.image.astype(np.float32))
    write_image(tmp_path / "frame.exr", frame.astype(np.float32))
    argv = [str(path), str(tmp_path / "truth.exr"), str(tmp_path / "frame.exr"), "--out", str(tmp_path / "out")]
    assert translucency_check.main(argv) == 0
    out = capsys.readouterr().out
    assert "frame " in out and all(f"{name} " in out for name in translucency_check.MODELS)
    pngs = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert pngs == sorted(f"{name}.png" for name in ("truth", *translucency_check.MODELS))


def test_near_light_check_monte_carlo_is_the_half_space(capsys):
    """The tool's Monte Carlo against Chandrasekhar's half-space: a view wide enough to hold the light
    that enters within its radius sees int E(r) f(1, mu0(r)) dA, f = a/(4 pi) H(1) H(mu0) / (1 + mu0);
    and the tool runs against it (no truth) with one technique."""
    from skinlab.scene.optics.boundary import chandrasekhar_h
    from tools import near_light_check as nl

    h, albedo, mfp, i0, radius = 2.0, (0.89, 0.69, 0.49), (1.3, 0.95, 0.67), 1e-5, 10.0
    img = nl.half_space_mc(h, albedo, mfp, i0, 16, 40.0, 150_000, radius_mm=radius)
    got = img.sum((0, 1)) * (40.0 / 16 * 1e-3) ** 2  # W/sr leaving straight up
    r = np.linspace(0.0, radius, 4001)
    mu0 = h / np.hypot(r, h)
    e = i0 * 1e6 * h / (r * r + h * h) ** 1.5  # W/m^2 on the surface
    for c, a in enumerate(albedo):
        f = a / (4 * np.pi) * chandrasekhar_h(a, 1.0) * chandrasekhar_h(a, mu0) / (1 + mu0)
        want = np.trapezoid(e * f * 2 * np.pi * r, r) * 1e-6  # mm^2 -> m^2
        assert got[c] == pytest.approx(want, rel=0.03), c
    assert nl.main(["--photons", "3000", "--techniques", "none", "--no-truth"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[1].startswith("point-light-skin1: light 2 mm above the slab") and "Monte Carlo" in out[1]
    assert out[2].startswith("none ") and out[2].count(" rings (mm):") == 1 and "8.65-13" in out[2]
