"""The accuracy/time ledger (`skinlab bench accuracy`): what each way of rendering subsurface
scattering costs in frame time and what it gets wrong, on the head and the bunny.

For every setting of the sweep (no scattering; the per-pixel tint; texture-space diffusion over K,
irradiance size and tap count; screen-space SSS over its tap presets; the brute-force exact
texture-space convolution, which is the image reference):

* **time**: ``warmup`` frames first (program compiles, uploads, stretch maps), then the median,
  10th and 90th percentile of ``FrameTimings.frame_ms`` over the timed frames of
  ``renderer.render(scene, settings, readback=False)``: the sum of the per-pass times, from GPU timer
  queries where the GPU has them, else (Mesa llvmpipe) wall time with ``glFinish`` after each pass
  (the ``clock`` column says which). Per-pass medians are kept too.
* **image error** against the exact reference of the same scene and image size, on linear HDR
  (``FrameResult.hdr``) over the lit surface pixels: reference coverage alpha > 0 and reference
  luminance above ``LUM_FRACTION`` of its 99th percentile. ``image_rel_l1`` = sum |img - ref| /
  sum ref (RGB summed over those pixels); ``image_max_rel`` / ``image_p95_rel``: the largest / 95th
  percentile per-pixel sum_c |img - ref| / sum_c ref.
* **profile error** against the Monte Carlo random walk (skinlab/scene/optics/montecarlo.py) for the
  scattering material's medium, as the relative L1 of the *edge response* (the fraction of a
  lit half-plane's light leaving at signed distance x past the shadow edge, per channel):
  ``int |E_tech - E_mc| dx / int |H - E_mc| dx`` over x in [-L, L] (L = 50 mean free paths of the
  channel), H the hard step of no scattering; averaged over the scattering channels. No scattering
  (and the tint, which does not spread light) scores exactly 1; a perfect profile 0. The edge
  response is what a shadow boundary shows on screen, it accepts a delta (identity weight), a
  Gaussian sum and a tabulated radial profile alike, and it integrates the MC noise away.
  Each technique gives its own edge response from the frame plan it rendered
  (``Technique.edge_response``, skinlab/render/techniques/<name>/): for "tsd" the Gaussian kernel the
  frame actually used (after the planner folded sub-texel Gaussians into the unblurred term; no
  blur pass at all = a delta), for "exact" the material's model profile, for "none"/"tint" a delta
  (the tint shifts colour but moves no light), for "ssss" the frame's 1-D screen-space kernel
  (skinlab/scene/optics/ssss.py separable_edge_response; an edge along a screen axis, the separable
  kernel's best case).
  ``profile_err_model`` is the same measure against the material's own model profile instead of
  Monte Carlo: the technique's approximation error alone, without the model's.

A setting that fails to render is recorded as an ``error`` row and the sweep goes on. Without a
working exact reference the most accurate tsd setting (largest irradiance
texture, largest K) stands in as a *proxy* reference, named in the ``reference`` column.

This module is the run loop (:func:`run_sweep`); the parts have one module each: sweep.py (Sweep,
Setting: what is measured), measure.py (timing a setting), image_error.py, profile_error.py (Monte
Carlo and model edge responses), ledger_analysis.py (Pareto front, slopes, recommendations),
ledger_csv.py, ledger_markdown.py, ledger_plots.py and ledger_files.py (writing them), peer.py
(the pyrender peer).
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from .image_error import image_error, lit_mask
from .ledger_analysis import error_key, log_slope, pareto_front, recommendations, usable
from .ledger_csv import NUMERIC_COLUMNS, csv_columns, csv_text
from .ledger_files import write_ledger
from .measure import measure_setting
from .profile_error import edge_error, edge_response, fit_kernel, model_reference, profile_reference
from .sweep import (
    SWEEPS,
    TINY,
    Setting,
    Sweep,
    proxy_reference,
    resolve_scene,
    scene_label,
    sheet_settings,
    sweep_settings,
)
from .truth_ledger import (
    error_map_sheet,
    load_truth,
    truth_context,
    truth_errors,
    write_error_map,
    write_flip_map,
)

__all__ = [  # the ledger's public names, importable from here as before the split
    "csv_columns",
    "NUMERIC_COLUMNS",
    "SWEEPS",
    "TINY",
    "Setting",
    "Sweep",
    "csv_text",
    "edge_error",
    "edge_response",
    "fit_kernel",
    "image_error",
    "log_slope",
    "model_reference",
    "pareto_front",
    "recommendations",
    "resolve_scene",
    "run_sweep",
    "sweep_settings",
    "usable",
    "error_key",
    "write_ledger",
]


def _loadavg():
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return None


def _first_line(exc: BaseException) -> str:
    text = f"{type(exc).__name__}: {exc}".strip()
    return text.splitlines()[0][:300] if text else type(exc).__name__


def _same_images(scene_rows: dict, digests: dict) -> None:
    """A row whose compared frame is bit-identical to an earlier row's says so (``same_image_as``)."""
    first: dict = {}
    for st, row in scene_rows.items():
        d = digests.get(st)
        if d is None:
            continue
        if d in first:
            row["same_image_as"] = first[d]
        else:
            first[d] = st.label


def _digest(a: np.ndarray) -> str:
    import hashlib

    return hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()


def _same_size_partner(st: Setting, scene_rows: dict, hdrs: dict, ref_tech: str | None):
    """The image reference's frame whose settings share this setting's shared parameter columns
    (e.g. an irradiance size), for a setting of another technique that has such columns."""
    if ref_tech is None or st.technique == ref_tech:
        return None
    from .sweep import _style

    mine, theirs = st.style.columns, _style(ref_tech).columns
    shared = [c for c in mine if c in theirs]
    if not shared:
        return None
    cells = st.cells()
    for other, r in scene_rows.items():
        if other.technique == ref_tech and r["status"] == "ok" and other in hdrs:
            oc = other.cells()
            if all(oc[c] == cells[c] for c in shared):
                return hdrs[other]
    return None


def run_sweep(
    sweep: Sweep,
    out: Path,
    scenes: tuple[str, ...] | None = None,
    peer: bool = True,
    progress: bool = True,
    images: bool = True,
    command: str | None = None,
    references: bool = False,
    blender: bool | tuple = False,
) -> dict:
    """Run the whole ledger and write DIR/ledger.csv, ledger.md, ledger.html, ledger.json, pareto.png and
    cost.png; with the sweep's truth, error_maps/, flip_maps/, error_maps.png and profiles.png.
    references: path-trace the references that are not cached yet (else a scene without a cached
    reference has no truth columns). blender: Blender's EEVEE and Cycles as peer rows in the same run
    (skinlab/bench/blender_peer.py; True: the sweep's PEER_SETTINGS, or a tuple of PeerSetting)."""
    from tqdm import tqdm

    from skinlab.gl.context import create_headless_context, describe
    from skinlab.render.registry import get_technique
    from skinlab.render.renderer import Renderer
    from skinlab.render.scattering import effective_material
    from skinlab.render.settings import RenderSettings
    from skinlab.scene.optics.material_medium import material_medium
    from skinlab.scene.scenefile import load_scene
    from skinlab.truth.metrics import relative_map

    from .sweep import reference_technique

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = tuple(scenes or sweep.scenes)
    paths = {s: resolve_scene(s) for s in scenes}
    settings = sweep_settings(sweep)
    ref_tech = reference_technique()
    t_start = time.perf_counter()
    load_start = _loadavg()
    ctx = create_headless_context()
    gl = describe(ctx)
    renderer = Renderer(ctx)
    renderer.reuse = False  # each setting's cost is that of a full frame (no pass kept from the last)
    peers = None
    if blender:
        from .blender_peer import LedgerPeers

        peers = LedgerPeers(sweep.name, None if blender is True else tuple(blender))
    rows: list[dict] = []
    truth_notes: dict[str, str] = {}
    truth_quiet: dict[str, str] = {}  # scenes compared with a quieter reference than the sweep's
    truth_scenes: dict[str, dict] = {}  # per scene: what its truth took, its edge region, what it tests
    profiles: dict[str, dict] = {}  # per scene: {"truth": Profile, setting label: Profile}
    sheet: dict[str, dict[str, np.ndarray]] = {}
    on_sheet = set(sheet_settings(settings))
    bar = tqdm(
        total=len(settings) * len(scenes),
        file=sys.stderr,
        unit="setting",
        disable=not progress,
        desc="ledger",
        dynamic_ncols=True,
    )
    try:
        for sname in scenes:
            label = scene_label(sname)
            scene = load_scene(paths[sname])
            # the scene's (first) scattering material, as the scene file has it: its medium is what the
            # profile errors are measured for, its own model is the model reference
            base_node = next((n for n in scene.mesh_nodes() if n.material.has_subsurface), None)
            base_mat = base_node.material if base_node is not None else None
            pref = mref = base_medium = None
            if base_mat is not None:
                base_medium = material_medium(base_mat.values)
                bar.set_postfix_str(f"{label}: Monte Carlo reference")
                try:
                    pref = profile_reference(base_medium, sweep.photons, out / "mc_cache")
                    mref = model_reference(base_mat["sss_model"], base_medium)
                except Exception as exc:
                    print(f"profile references for {label} failed: {_first_line(exc)}", file=sys.stderr)
                    base_mat = None
            truth = tctx = None
            if sweep.truth is not None:
                bar.set_postfix_str(f"{label}: path-traced reference")
                try:
                    truth = load_truth(scene, sweep.truth, render=references, progress=progress)
                except Exception as exc:
                    truth_notes[label] = f"the path-traced reference failed: {_first_line(exc)}"
                if truth is not None and truth.meta.get("variant", "scalar_rgb") != "scalar_rgb":
                    truth_quiet[label] = (
                        f"compared with a quieter reference rendered elsewhere ({truth.meta.get('spp')} spp, "
                        f"{truth.meta.get('variant')}; `QUIET_REFERENCES`, tools/gpu_reference.py)"
                    )
                if truth is None and label not in truth_notes:
                    truth_notes[label] = (
                        "no cached path-traced reference at "
                        f"{sweep.truth.size[0]}x{sweep.truth.size[1]}, {sweep.truth.spp} spp: run with --references"
                    )
            if truth is not None:
                # the plain frame (no scattering) finds the light edges where the scene declares none
                tw, th = truth.image.shape[1::-1]
                plain_rs = RenderSettings(
                    tw, th, shadow_size=sweep.shadow_size, supersample=sweep.truth.supersample, sss_model="none"
                )
                plain = renderer.render(scene, plain_rs, readback=("hdr",)).hdr
                tctx = truth_context(scene, truth, plain)
                spec = tctx.spec
                truth_scenes[label] = {
                    "spp": truth.meta.get("spp"),
                    "passes": truth.pass_set.count,
                    "seconds": truth.meta.get("seconds"),
                    "variant": truth.meta.get("variant", "scalar_rgb"),
                    "noise": truth.noise.get("rel_l1"),
                    "noise_block": truth.noise.get("rel_l1_block"),
                    "edge_mm": tctx.edge_mm,
                    "edge_from": tctx.edge_from,
                    "edge_pixels": int(tctx.edge.sum()),
                    "tests": spec.tests if spec is not None else "",
                    "profile": spec.profile if spec is not None else "none",
                }
                if tctx.profile is not None:
                    profiles[label] = {"truth": tctx.profile, "kind": spec.profile}
            hdrs: dict[Setting, np.ndarray] = {}
            digests: dict[Setting, str] = {}
            scene_rows: dict[Setting, dict] = {}
            for st in settings:
                bar.set_postfix_str(f"{label}: {st.label}")
                row = {
                    "scene": label,
                    "setting": st.label,
                    "technique": st.technique,
                    **st.cells(),
                    "width": sweep.size[0],
                    "height": sweep.size[1],
                    "status": "ok",
                    "error": "",
                }
                try:
                    rs = st.render_settings(sweep)
                    row["model"] = (
                        effective_material(base_node, rs)["sss_model"]
                        if base_node is not None and get_technique(st.technique).scatters
                        else "none"
                        if base_node is not None
                        else ""
                    )
                    m = measure_setting(renderer, scene, rs, sweep.warmup, sweep.frames, sweep.budget_s)
                    row.update(
                        {
                            k: m[k]
                            for k in (
                                "frames",
                                "frame_ms_median",
                                "frame_ms_p10",
                                "frame_ms_p90",
                                "wall_ms_median",
                                "technique_ms_median",
                                "clock",
                                "blur_levels",
                            )
                        }
                    )
                    row["passes"] = m["passes"]
                    hdrs[st] = m["hdr"]
                    digests[st] = _digest(m["hdr"])
                    if tctx is not None:
                        # an untimed frame at the reference's size, supersampled like the truth's
                        # box-filtered pixels, compared with the truth
                        small_rs = st.render_settings(sweep, truth.image.shape[1::-1], sweep.truth.supersample)
                        small = renderer.render(scene, small_rs, readback=("hdr",)).hdr
                        got = truth_errors(small, tctx)
                        prof = got.pop("profile", None)
                        row.update(got)
                        if prof is not None:
                            profiles[label][st.label] = prof
                        digests[st] = _digest(small)
                        safe = st.label.replace(" ", "-")
                        write_error_map(out / "error_maps" / f"{label}-{safe}.png", small, truth)
                        write_flip_map(out / "flip_maps" / f"{label}-{safe}.png", small, tctx)
                        if st in on_sheet:
                            sheet.setdefault(label, {})[st.label] = relative_map(small, truth.image)
                    if images:
                        from skinlab.image_output import write_image

                        safe = st.label.replace(" ", "-")
                        write_image(out / "images" / f"{label}-{safe}.png", m["ldr"])
                    # profile error against Monte Carlo and against the material's own model profile
                    if base_mat is not None:
                        fn = edge_response(st.technique, row["model"], base_medium, m["frame_plan"])
                        row["profile_err_mc"] = edge_error(pref, fn) if fn is not None else math.nan
                        row["profile_err_model"] = (
                            edge_error(mref, fn) if (fn is not None and mref is not None) else math.nan
                        )
                except Exception as exc:  # a failing technique is a row, not the end of the sweep
                    row["status"] = "error"
                    row["error"] = _first_line(exc)
                scene_rows[st] = row
                rows.append(row)
                bar.update(1)
            _same_images(scene_rows, digests)
            # image errors against the reference (the exact one, else the proxy)
            ref_st = settings[0] if scene_rows[settings[0]]["status"] == "ok" else proxy_reference(settings)
            if ref_st is not None and scene_rows[ref_st]["status"] != "ok":
                ref_st = None
            ref = hdrs.get(ref_st) if ref_st is not None else None
            mask = lit_mask(ref) if ref is not None else None
            for st, row in scene_rows.items():
                row["reference"] = ref_st.label if ref_st is not None else ""
                if ref is not None and st in hdrs:
                    row.update(image_error(hdrs[st], ref, mask))
                # against the image reference at the same shared settings (an irradiance size): the
                # technique's own error without the reference's texture-resolution error
                same = _same_size_partner(st, scene_rows, hdrs, ref_tech) if st in hdrs else None
                if same is not None:
                    row["image_rel_l1_same_size"] = image_error(hdrs[st], same)["image_rel_l1"]
            del hdrs
            if peers is not None:  # Blender's rows, against the same truth and image reference
                prows, pmaps = peers.scene_rows(scene, label, sweep, truth, tctx, out, renderer, ref, mask,
                                                profiles.get(label), progress=bar.set_postfix_str)  # fmt: skip
                rows += prows
                if pmaps:
                    sheet.setdefault(label, {}).update(pmaps)
    finally:
        bar.close()
        renderer.release()
        if peers is not None:
            peers.close()
    sweep_s = time.perf_counter() - t_start
    if sheet:
        error_map_sheet(
            sheet,
            out / "error_maps.png",
            "signed relative difference against the path-traced truth per pixel (red: brighter, blue: darker)",
        )
    peer_res = None
    if peer:
        try:
            from skinlab.bench.peer import peer_bench

            peer_res = peer_bench(sweep.size, sweep.peer_frames)
        except Exception as exc:
            peer_res = {"error": _first_line(exc)}
    meta = {
        "sweep": sweep.name,
        "gl": gl,
        "cpus": os.cpu_count(),
        "size": list(sweep.size),
        "shadow_size": sweep.shadow_size,
        "warmup": sweep.warmup,
        "frames": sweep.frames,
        "budget_s": sweep.budget_s,
        "photons": sweep.photons,
        "scenes": [scene_label(s) for s in scenes],
        "truth": None
        if sweep.truth is None
        else {
            "size": list(sweep.truth.size),
            "spp": sweep.truth.spp,
            "passes": sweep.truth.passes,
            "supersample": sweep.truth.supersample,
            "missing": truth_notes,
            "quiet": truth_quiet,
            "scenes": truth_scenes,
        },
        "sweep_s": sweep_s,
        "total_s": time.perf_counter() - t_start,
        "peer": peer_res,
        "blender": None if peers is None else peers.meta,
        "loadavg_start": load_start,
        "loadavg_end": _loadavg(),
        "command": command,
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    }
    return write_ledger(rows, meta, out, sweep, profiles)
