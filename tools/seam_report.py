"""A one-off analysis, not a feature: UV seams in texture-space diffusion (docs/tsd.md "UV seams"): per
reference scene, the seam geometry (seam edges, sides continued, band, extension triangles, the one-off
unfolding time), the cost of the passes with seams on and off (interleaved, median of --rounds frames,
every pass run), the gutter of the UV layout (how far its texels are from a chart), and with --truth the
error against the cached 96x96 path-traced references with seams off and on (the ledger's truth_errors,
as tools/truth_table.py).

    .venv/bin/python -m tools.seam_report [--scenes a,b] [--size 320] [--rounds 3] [--truth]
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from scipy.ndimage import distance_transform_edt

from skinlab.bench.sweep import QUICK
from skinlab.bench.truth_ledger import REFERENCE_SCENES, TruthSpec, load_truth, truth_errors
from skinlab.gl.context import create_headless_context
from skinlab.render.renderer import Renderer
from skinlab.render.settings import RenderSettings
from skinlab.render.techniques.tsd.passes import frame_nodes, read_texture
from skinlab.scene.mesh import with_atlas
from skinlab.scene.scenefile import load_scene
from skinlab.scene.uv_seams import seam_extension


def pass_key(name: str) -> str:
    """tsd_blur[bunny]2 -> tsd_blur2"""
    return name.split("[")[0] + (name.split("]")[1] if "]" in name else "")


def report(r: Renderer, name: str, size: int, rounds: int, truth: bool) -> None:
    scene = load_scene(REFERENCE_SCENES / f"{name}.toml")
    node = scene.mesh_nodes()[0]
    mesh = with_atlas(node.mesh)
    on = RenderSettings.for_technique("tsd", size, size, seams=True)
    seam = next(p for p in r.plan(scene, on).passes if p.kind == "tsd_seams")
    ext = seam.params.seams
    t0 = time.perf_counter()
    seam_extension(mesh, ext.band_uv)
    build = time.perf_counter() - t0
    n = seam.params.size
    print(
        f"{name}: {len(mesh.indices)} triangles, {len(ext.seam_pairs)} seam edges ({len(set(ext.owner.tolist()))} "
        f"of {2 * len(ext.seam_pairs)} sides continued), band {ext.band_uv * n:.0f} texels, {ext.triangles} extension "
        f"triangles, unfolding {build * 1e3:.0f} ms (once)"
    )
    times: dict = {True: {}, False: {}}
    r.reuse = False
    for _ in range(rounds):
        for seams in (False, True):
            res = r.render(scene, RenderSettings.for_technique("tsd", size, size, seams=seams), readback=False)
            for p in res.timings.passes:
                times[seams].setdefault(pass_key(p.name), []).append(p.cpu_ms)
    med = {s: {k: float(np.median(v)) for k, v in times[s].items()} for s in times}
    every = [k for k in med[True] if k.startswith("tsd") and k not in ("tsd_stretch", "tsd_seams")]
    blur = [k for k in every if k.startswith("tsd_blur")]

    def total(s, keys):
        return sum(med[s].get(k, 0.0) for k in keys)

    print(
        f"  once: seam map {med[True]['tsd_seams']:.1f} ms, stretch {med[True]['tsd_stretch']:.1f} vs "
        f"{med[False]['tsd_stretch']:.1f} ms; every frame: dilate {med[True]['tsd_dilate']:.1f} vs "
        f"{med[False]['tsd_dilate']:.1f} ms, blurs {total(True, blur):.1f} vs {total(False, blur):.1f} ms; "
        f"frame {sum(med[True].values()):.0f} vs {sum(med[False].values()):.0f} ms (seams on vs off)"
    )
    r.render(scene, on, readback=False)
    t = frame_nodes(r.last_frame)[node.uid].targets
    real = read_texture(t.raw)[..., 3] > 0
    marked = read_texture(t.seam.texture)[..., 3] > 0.5
    d = distance_transform_edt(~real)
    gut = ~real
    near = " / ".join(f"{100 * (gut & (d <= k)).sum() / gut.sum():.0f} %" for k in (1, 2, 4, 8))
    print(
        f"  gutter {100 * gut.mean():.0f} % of the texture; within 1 / 2 / 4 / 8 texels of a chart: {near}; "
        f"farthest {d.max():.0f} texels; the seam map fills {100 * marked.sum() / gut.sum():.0f} % of it"
    )
    if truth:
        ref = load_truth(scene, TruthSpec((96, 96), 256), progress=False)
        if ref is None:
            print("  no cached 96x96 reference (skinlab bench accuracy --quick --references)")
            return
        for technique in ("tsd", "exact"):
            row = []
            for seams in (False, True):
                rs = RenderSettings.for_technique(technique, 96, 96, shadow_size=QUICK.shadow_size, seams=seams)
                e = truth_errors(r.render(scene, rs, readback=("hdr",)).hdr, ref)
                energy = " ".join(f"{100 * e[f'truth_energy_{c}']:+.1f}" for c in "rgb")
                row.append(f"{100 * e['truth_rel_l1_block']:.2f} % (energy {energy})")
            print(
                f"  truth, {technique}: 4x4 blocks seams off {row[0]}, on {row[1]}; "
                f"noise {100 * ref.noise['rel_l1_block']:.1f} %"
            )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.seam_report", description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenes", default="bunny-marble,bunny-skimmilk,bunny-ketchup,head-skin1-matched")
    ap.add_argument("--size", type=int, default=320, help="image pixels per side (default 320)")
    ap.add_argument("--rounds", type=int, default=3, help="frames per setting, interleaved (default 3)")
    ap.add_argument("--truth", action="store_true", help="also the error against the cached references")
    a = ap.parse_args(argv)
    r = Renderer(create_headless_context())
    for name in a.scenes.split(","):
        report(r, name, a.size, a.rounds, a.truth)
    r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
