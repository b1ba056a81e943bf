"""A one-off analysis, not a feature: the boundary of a scattering medium on its own: a flat, semi-infinite
slab of a reference scene's material (default head-skin1: skin1 at index 1.3 under a rough dielectric,
roughness 0.45), path traced by Mitsuba (tiny renders, cached like every reference) against the NumPy
boundary model and Skinlab's frame. Used for docs/ground-truth.md "The rough boundary at index 1.3".

    python -m tools.boundary_slab [SCENE] [--roughness R,R,...] [--technique tsd] [--spp 1024] [--angles 0,45,70]

Rows: the slab under a uniform sky of radiance 1 seen from 0, 45 and 70 degrees (by reciprocity its
directional albedo at that cosine, boundary reflection included: 8x8 pixels, 1024 spp), and lit by
one directional light of irradiance 1 from 0, 45 and 70 degrees seen from above (16x16, 1024 spp);
`dark` is the same boundary over a medium that returns nothing (what the boundary itself reflects).
Model (sky rows only): multiple scattering A_ms(mu) + single scattering A_ss(mu) + the boundary's
reflectance R(mu) (skinlab/scene/optics/boundary.py, rough_dielectric.py). `--roughness` renders the slab
again at other roughnesses (the truth's boundary: GGX alpha = roughness^2, smooth below 0.032).
The standard error is from the difference of the reference's two halves. A directional light behind
a smooth dielectric never reaches the medium in the path tracer (no path connects to a delta light
through a delta boundary): those rows are left out."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from skinlab.bench.truth_ledger import REFERENCE_SCENES
from skinlab.gl.context import create_headless_context
from skinlab.render.boundary import boundary_ggx_alpha
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import CameraNode, LightNode, MeshNode, Scene
from skinlab.scene.materials import Material
from skinlab.scene.optics.boundary import boundary_tables, single_ambient_albedo
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.rough_dielectric import SMOOTH_ALPHA, rough_albedos
from skinlab.scene.primitives import box_mesh
from skinlab.scene.scenefile import load_scene
from skinlab.scene.transform import look_at_rotation
from skinlab.truth.reference import ReferenceRequest, render_reference


def slab(material: Material, view_deg: float, light_deg: float | None) -> Scene:
    s = Scene("boundary-slab", 1.0)
    s.environment.ambient = np.full(3, 1.0 if light_deg is None else 0.0)
    s.add(MeshNode("slab", box_mesh((800.0, 800.0, 400.0)), material, translation=(0.0, 0.0, -200.0)))
    cam = CameraNode("cam", yfov=math.radians(2.0), znear=100.0, zfar=3000.0)
    t = math.radians(view_deg)
    cam.look_at((0.0, 1000.0 * math.sin(t), 1000.0 * math.cos(t)), (0.0, 0.0, 0.0))
    s.add(cam)
    if light_deg is not None:
        t = math.radians(light_deg)
        key = LightNode("sun", "directional", intensity=1.0, cast_shadow=False)
        key.rotation = look_at_rotation(np.zeros(3), np.array([0.0, math.sin(t), -math.cos(t)]))
        s.add(key)
    return s


def model_sky(material: Material, mu: float) -> np.ndarray:
    medium = material_medium(material.values)
    ga = boundary_ggx_alpha(material)
    t = boundary_tables(medium.alpha_arr, material["subsurface_color"], medium.eta, ga)
    ms = np.array([np.interp(mu, np.linspace(0, 1, len(t.entry)), t.entry[:, c]) for c in range(3)])
    ms = ms * np.asarray(material["subsurface_color"])
    ss = np.array([float(single_ambient_albedo(a, medium.eta, mu)) for a in medium.alpha_arr])
    spec = float(rough_albedos(mu, ga if ga >= SMOOTH_ALPHA else 0.0, medium.eta)[0]) if medium.eta > 1 else 0.0
    return ms + ss + spec


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.boundary_slab", description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", default="head-skin1")
    ap.add_argument("--roughness", default="", help="comma-separated roughnesses to render besides the material's")
    ap.add_argument("--technique", default="tsd")
    ap.add_argument("--spp", type=int, default=1024, help="samples per pixel of the truths (default 1024)")
    ap.add_argument("--angles", default="0,45,70", help="comma-separated view and light angles, degrees")
    args = ap.parse_args(argv)
    angles = [float(x) for x in args.angles.split(",") if x]
    scene = load_scene(REFERENCE_SCENES / f"{args.scene}.toml")
    base = next(n.material for n in scene.mesh_nodes() if n.material.has_subsurface)
    rough = [float(base["roughness"])] + [float(x) for x in args.roughness.split(",") if x]
    r = Renderer(create_headless_context())
    fmt = lambda v: " ".join(f"{x:7.4f}" for x in v)  # noqa: E731
    pct = lambda v: " ".join(f"{100 * x:+6.1f}" for x in v)  # noqa: E731
    print(f"{args.scene}: eta {material_medium(base.values).eta:.3f}; frame: {args.technique}, 4x4 supersampled")
    for rg in rough:
        for name, colour in (("medium", None), ("dark", (1e-4,) * 3)):
            mat = Material(name, dict(base.values))
            mat.values["roughness"] = rg
            if colour is not None:
                mat.values["subsurface_color"] = colour
                mat.values["base_color"] = colour
            cases: list[tuple[str, float, float | None]] = [("sky", v, None) for v in angles]
            if rg * rg >= SMOOTH_ALPHA or material_medium(mat.values).eta <= 1.0:
                cases += [("sun", 0.0, a) for a in angles]
            for kind, view, light in cases:
                n = 8 if light is None else 16
                ref = render_reference(
                    slab(mat, view, light), ReferenceRequest(n, n, spp=args.spp, passes=2), progress=False
                )
                assert ref is not None  # rendered when not cached
                got = ref.image[..., :3].reshape(-1, 3).mean(0)
                se = np.abs(ref.half_a - ref.half_b)[..., :3].reshape(-1, 3).mean(0) / 2 / n
                rs = RenderSettings.for_technique(args.technique, n, n, supersample=4)
                frame = r.render(slab(mat, view, light), rs, readback=("hdr",)).hdr[..., :3].reshape(-1, 3).mean(0)
                where = f"view {view:2.0f}" if light is None else f"light {light:2.0f}"
                line = f"rough {rg:4.2f} {name:6s} {kind} {where}: truth {fmt(got)} (se {pct(se / got)} %)"
                line += f"  frame {pct(frame / got - 1)} %"
                if light is None and colour is None:
                    line += f"  model {pct(model_sky(mat, math.cos(math.radians(view))) / got - 1)} %"
                print(line, flush=True)
    r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
