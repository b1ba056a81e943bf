"""The cost tools at a tiny size: their variants are declared (measurement defines the shaders read,
a technique option, materials without maps), not patched into copies of the shaders."""

import numpy as np
import pytest

from skinlab.gl.shader_source import ShaderLibrary
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.technique import HOOK_INCLUDE, PLAIN_HOOK
from skinlab.scene.scenefile import load_scene
from tools import forward_cost, irradiance_cost
from tools.cost_variants import measure_library, without_maps

HOOK = {HOOK_INCLUDE: PLAIN_HOOK}


def test_a_measure_define_reaches_its_pass_only_and_must_be_read():
    lib = measure_library(irradiance_cost.IRR, irradiance_cost.MEASURES["pcf_1tap"])
    assert "#define MEASURE_PCF_1TAP" in lib.expand(irradiance_cost.IRR).text
    assert "#define MEASURE_PCF_1TAP" not in lib.expand(forward_cost.FWD, aliases=HOOK).text  # shadow.glsl too
    assert "#define MEASURE_" not in ShaderLibrary().expand(irradiance_cost.IRR).text  # never set otherwise
    with pytest.raises(SystemExit, match="passes/forward.frag: no shader of the pass reads MEASURE_NOTHING"):
        measure_library(forward_cost.FWD, {"MEASURE_NOTHING": 1})


def test_the_variants_change_what_they_say(ctx):
    scene = load_scene(None)
    st = RenderSettings(24, 24, sss_model="none")
    base = Renderer(ctx)
    raster = Renderer(ctx, measure_library(forward_cost.FWD, {"MEASURE_RASTER_ONLY": 1}))
    a = base.render(scene, st, readback=("hdr",)).hdr
    b = raster.render(scene, st, readback=("hdr",)).hdr
    assert not np.allclose(a, b)  # the forward pass wrote its inputs, not the shading
    bare = without_maps(load_scene(None), forward_cost.MAPS)
    assert all(n.material["normal_map"] is None and n.material["base_color_map"] is None for n in bare.mesh_nodes())
    assert any(n.material["normal_map"] is not None for n in scene.mesh_nodes())  # the head has maps to take out
    base.release()
    raster.release()


def test_forward_cost_runs_tiny(capsys):
    assert forward_cost.main(["--size", "16", "--rounds", "1"]) == 0
    out = capsys.readouterr().out
    for name in ("base", "aniso1", "no_maps", "no_prepass", "raster_only"):
        assert f"  {name:<12}" in out
    assert "aniso1 vs base, HDR" in out


def test_irradiance_cost_runs_tiny(capsys):
    argv = ["--size", "16", "--tsd-size", "64", "--rounds", "1", "--scene", "reference/slab-thin-backlit-skin1"]
    assert irradiance_cost.main(argv) == 0
    out = capsys.readouterr().out
    for name in ("base", "pcf_1tap", "no_translucency", "no_maps", "raster_only"):
        assert f"  {name:<16}" in out
    assert "light-through record's fill" in out  # the thin slab lets light through: the fill is timed
    assert irradiance_cost.main(["--coverage", "--tsd-size", "128", "--rounds", "1"]) == 0
    shares = [float(line.split("%")[0].split()[-1]) for line in capsys.readouterr().out.splitlines() if "UVs x" in line]
    assert len(shares) == 4 and shares == sorted(shares, reverse=True) and shares[-1] < shares[0] / 10


def test_forward_cost_times_a_technique_s_translucency_by_its_parts(ctx, capsys):
    from skinlab.render.translucency import DEFINE

    hook = "techniques/ssss/forward.glsl"
    for defines in forward_cost.TRANSLUCENCY_PARTS.values():  # each part's define is read with the hook's translucency
        measure_library(forward_cost.FWD, defines, hook, {DEFINE: 1})
    # a define no shader of the pass reads is refused (lib/sss_translucency.glsl is in every forward pass's
    # source since single scattering along the light's path reads its distance maps, so its parts' defines are)
    with pytest.raises(SystemExit, match="no shader of the pass reads MEASURE_NO_SUCH_PART"):
        measure_library(forward_cost.FWD, {"MEASURE_NO_SUCH_PART": 1})
    # taking the slab tables out changes the back-lit slab's frame (the variant is what it says)
    scene = load_scene("reference/slab-thin-backlit-skin1")
    st = RenderSettings.for_technique("ssss", 24, 24, shadow_size=256)
    parts = forward_cost.TRANSLUCENCY_PARTS
    runs = [
        Renderer(ctx),
        Renderer(ctx, measure_library(forward_cost.FWD, parts["no_slab_through"], hook, {DEFINE: 1})),
    ]
    a, b = (r.render(scene, st, readback=("hdr",)).hdr for r in runs)
    assert not np.allclose(a, b)
    for r in runs:
        r.release()
    argv = ["--translucency", "ssss", "--size", "16", "--rounds", "1", "--scene", "reference/slab-thin-backlit-skin1"]
    assert forward_cost.main(argv) == 0
    out = capsys.readouterr().out
    for name in ("base", "off", *parts, "all_three"):
        assert f"  {name:<16}" in out
    with pytest.raises(SystemExit, match="tsd's forward pass adds no light through thin parts here"):
        forward_cost.main(["--translucency", "tsd", "--size", "16", "--rounds", "1"])  # its irradiance pass does
    with pytest.raises(SystemExit, match="'tint' has no translucency setting"):
        forward_cost.main(["--translucency", "tint", "--size", "16", "--rounds", "1"])


def test_orbit_cost_runs_tiny_and_reads_its_defines(capsys):
    from pathlib import Path

    import skinlab
    from tools import orbit_cost

    here = Path(skinlab.__file__).resolve().parents[1]  # a checkout holding skinlab/shaders: these shaders again
    assert orbit_cost.main(["--size", "16", "--rounds", "1", "--against", str(here)]) == 0
    out = capsys.readouterr().out
    for name in ("base", "plain", "no_bounce", *orbit_cost.MEASURES, "against0"):
        assert f"  {name:<16}" in out
    assert "HDR relative difference max 0," in out  # the same shaders: the same image
    with pytest.raises(SystemExit, match="--against: no shaders under"):
        orbit_cost.main(["--size", "16", "--rounds", "1", "--only", "plain", "--against", str(here / "tests")])
