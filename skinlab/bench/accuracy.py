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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skinlab.bench.machine_load import load_average

from .image_error import image_error, lit_mask
from .ledger_analysis import error_key, log_slope, pareto_front, recommendations, usable
from .ledger_csv import NUMERIC_COLUMNS, csv_columns, csv_text
from .ledger_files import write_ledger
from .ledger_row import LedgerRow
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
    closeup_truth,
    error_map_sheet,
    load_truth,
    scene_truth_spec,
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


def _first_line(exc: BaseException) -> str:
    text = f"{type(exc).__name__}: {exc}".strip()
    return text.splitlines()[0][:300] if text else type(exc).__name__


def same_images(rows: list[LedgerRow], digests: dict[str, str]) -> list[LedgerRow]:
    """The rows, each whose compared frame (digests[setting label]) is bit-identical to an earlier row's
    saying so (``same_image_as``)."""
    first: dict[str, str] = {}
    out = []
    for r in rows:
        d = digests.get(r.setting)
        if d is not None and d in first:
            r = r.but(same_image_as=first[d])
        elif d is not None:
            first[d] = r.setting
        out.append(r)
    return out


def _digest(a: np.ndarray) -> str:
    import hashlib

    return hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()


def same_size_partner(st: Setting, measured: dict[Setting, LedgerRow], ref_tech: str | None) -> Setting | None:
    """The image reference's ok setting whose settings share this setting's shared parameter columns
    (e.g. an irradiance size), for a setting of another technique that has such columns."""
    if ref_tech is None or st.technique == ref_tech:
        return None
    from .sweep import _style

    mine, theirs = st.style.columns, _style(ref_tech).columns
    shared = [c for c in mine if c in theirs]
    if not shared:
        return None
    cells = st.cells()
    for other, r in measured.items():
        if other.technique == ref_tech and r.status == "ok":
            oc = other.cells()
            if all(oc[c] == cells[c] for c in shared):
                return other
    return None


def image_reference(settings: list[Setting], measured: dict[Setting, LedgerRow]) -> Setting | None:
    """The setting the scene's image errors are measured against: the exact reference (the first
    setting), else the proxy (sweep.proxy_reference), where it rendered; None where neither did."""
    ref = settings[0] if measured[settings[0]].status == "ok" else proxy_reference(settings)
    return ref if ref is not None and measured[ref].status == "ok" else None


def with_image_errors(
    measured: dict[Setting, LedgerRow], hdrs: dict[Setting, np.ndarray], ref_st: Setting | None, ref_tech: str | None
) -> list[LedgerRow]:
    """The scene's rows with their reference and their image errors against its frame (`hdrs`: the
    timed frames), and against the reference's frame at the same shared settings
    (``image_rel_l1_same_size``: the technique's own error without the reference's texture-resolution
    error)."""
    ref = hdrs.get(ref_st) if ref_st is not None else None
    mask = lit_mask(ref) if ref is not None else None
    out = []
    for st, row in measured.items():
        cells: dict = {"reference": ref_st.label if ref_st is not None else ""}
        if ref is not None and st in hdrs:
            cells.update(image_error(hdrs[st], ref, mask))
        partner = same_size_partner(st, measured, ref_tech) if st in hdrs else None
        if partner is not None and partner in hdrs:
            cells["image_rel_l1_same_size"] = image_error(hdrs[st], hdrs[partner])["image_rel_l1"]
        out.append(row.but(**cells))
    return out


TIMED_COLUMNS = ("frames", "frame_ms_median", "frame_ms_p10", "frame_ms_p90", "wall_ms_median", "technique_ms_median",
                 "clock", "blur_levels")  # fmt: skip


@dataclass
class ProfileReferences:
    """What one scene's profile errors are measured against: its first scattering material's medium, the
    Monte Carlo random walk's edge response for it (`mc`) and its own model's (`model`)."""

    node: object = None  # the scene's first mesh node with a scattering material
    medium: object = None
    mc: object = None
    model: object = None

    def errors(self, technique: str, model: str, frame_plan) -> dict:
        """The profile error columns of a frame (nan where the technique gives no edge response)."""
        if self.mc is None:
            return {}
        fn = edge_response(technique, model, self.medium, frame_plan)
        return {
            "profile_err_mc": edge_error(self.mc, fn) if fn is not None else math.nan,
            "profile_err_model": edge_error(self.model, fn)
            if (fn is not None and self.model is not None)
            else math.nan,
        }


class LedgerRun:
    """One run of the ledger: the renderer, the sweep's conditions, and what the scenes add beside their
    rows (the truths' notes and figures, the profiles, the error-map sheet)."""

    def __init__(self, sweep: Sweep, out: Path, images: bool, references: bool, progress: bool, say):
        from skinlab.gl.context import create_headless_context, describe
        from skinlab.render.renderer import Renderer

        self.sweep, self.out, self.images, self.references, self.progress = sweep, out, images, references, progress
        self.say = say  # shows what is being done (the progress bar's postfix)
        self.ctx = create_headless_context()
        self.gl = describe(self.ctx)
        self.renderer = Renderer(self.ctx)
        self.renderer.reuse = False  # each setting's cost is that of a full frame (no pass kept from the last)
        self.truth_notes: dict[str, str] = {}
        self.truth_quiet: dict[str, str] = {}  # scenes compared with a quieter reference than the sweep's
        self.truth_scenes: dict[str, dict] = {}  # per scene: what its truth took, its edge region, what it tests
        self.profiles: dict[str, dict] = {}  # per scene: {"truth": Profile, "kind": ..., setting label: Profile}
        self.sheet: dict[str, dict[str, np.ndarray]] = {}

    def profile_references(self, scene, label: str) -> ProfileReferences:
        """The scene's (first) scattering material as the scene file has it: its medium is what the profile
        errors are measured for, its own model is the model reference."""
        from skinlab.scene.optics.material_medium import material_medium

        node = next((n for n in scene.mesh_nodes() if n.material.has_subsurface), None)
        refs = ProfileReferences(node)
        if node is None:
            return refs
        refs.medium = material_medium(node.material.values)
        self.say(f"{label}: Monte Carlo reference")
        try:
            refs.mc = profile_reference(refs.medium, self.sweep.photons, self.out / "mc_cache")
            refs.model = model_reference(node.material["sss_model"], refs.medium)
        except Exception as exc:
            print(f"profile references for {label} failed: {_first_line(exc)}", file=sys.stderr)
            refs.mc = refs.model = None
        return refs

    def load_truth(self, scene, label: str):
        """The scene's path-traced reference at the sweep's truth size (the scene's own where its [measure]
        declares one: scene_truth_spec), or None (the reason noted)."""
        if self.sweep.truth is None:
            return None
        spec = scene_truth_spec(scene, self.sweep.truth)
        self.say(f"{label}: path-traced reference")
        truth = None
        try:
            truth = load_truth(scene, spec, render=self.references, progress=self.progress)
        except Exception as exc:
            self.truth_notes[label] = f"the path-traced reference failed: {_first_line(exc)}"
        if truth is not None and truth.meta.get("variant", "scalar_rgb") != "scalar_rgb":
            self.truth_quiet[label] = (
                f"compared with a quieter reference rendered elsewhere ({truth.meta.get('spp')} spp, "
                f"{truth.meta.get('variant')}; `QUIET_REFERENCES`, tools/gpu_reference.py)"
            )
        if truth is None and label not in self.truth_notes:
            self.truth_notes[label] = (
                f"no cached path-traced reference at {spec.size[0]}x{spec.size[1]}, {spec.spp} spp"
                + (f", rr_depth {spec.rr_depth}" if spec.rr_depth != 64 else "")
                + f": run with --references (or `skinlab reference SCENE {spec.command_options}`)"
            )
        return truth

    def truth_context(self, scene, label: str, truth):
        """What the scene's settings are measured against (the plain frame, no scattering, finds the light
        edges where the scene declares none); notes what the truth took and starts the scene's profiles."""
        from skinlab.render.settings import RenderSettings

        tw, th = truth.image.shape[1::-1]
        sw = self.sweep
        plain_rs = RenderSettings(
            tw, th, shadow_size=sw.shadow_size, supersample=sw.truth.supersample, sss_model="none"
        )
        plain = self.renderer.render(scene, plain_rs, readback=("hdr",)).hdr
        tctx = truth_context(scene, truth, plain)
        spec = tctx.spec
        self.truth_scenes[label] = {
            "size": [tw, th],
            "rr_depth": scene_truth_spec(scene, sw.truth).rr_depth,
            "closeup": closeup_truth(tctx),
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
            self.profiles[label] = {"truth": tctx.profile, "kind": spec.profile}
        return tctx

    def against_truth(self, scene, label: str, st: Setting, tctx, on_sheet: bool) -> tuple[dict, str]:
        """An untimed frame at the truth's size, supersampled like the truth's box-filtered pixels, compared
        with the truth: (its truth columns, its digest); its error and FLIP maps written."""
        truth = tctx.truth
        small_rs = st.render_settings(self.sweep, truth.image.shape[1::-1], self.sweep.truth.supersample)
        small = self.renderer.render(scene, small_rs, readback=("hdr",)).hdr
        got = truth_errors(small, tctx)
        prof = got.pop("profile", None)
        if prof is not None:
            self.profiles[label][st.label] = prof
        safe = st.label.replace(" ", "-")
        write_error_map(self.out / "error_maps" / f"{label}-{safe}.png", small, truth)
        write_flip_map(self.out / "flip_maps" / f"{label}-{safe}.png", small, tctx)
        if on_sheet:
            from skinlab.truth.metrics import relative_map

            self.sheet.setdefault(label, {})[st.label] = relative_map(small, truth.image)
        return got, _digest(small)

    def measure(self, scene, label: str, st: Setting, refs: ProfileReferences, tctx, on_sheet: bool):
        """One setting on one scene: (its row, its timed frame or None, the digest of its compared frame or
        None). A setting that raises is an ``error`` row with what was measured before."""
        from skinlab.render.registry import get_technique
        from skinlab.render.scattering import effective_material

        sw = self.sweep
        cells: dict = {"scene": label, "setting": st.label, "technique": st.technique, "params": st.cells(),
                       "width": sw.size[0], "height": sw.size[1]}  # fmt: skip
        hdr = digest = None
        try:
            rs = st.render_settings(sw)
            node = refs.node
            scatters = node is not None and get_technique(st.technique).scatters
            cells["model"] = effective_material(node, rs)["sss_model"] if scatters else "none" if node else ""
            m = measure_setting(self.renderer, scene, rs, sw.warmup, sw.frames, sw.budget_s)
            cells.update({k: m[k] for k in TIMED_COLUMNS}, passes_ms=m["passes"])
            hdr, digest = m["hdr"], _digest(m["hdr"])
            if tctx is not None:
                got, digest = self.against_truth(scene, label, st, tctx, on_sheet)
                cells.update(got)
            if self.images:
                from skinlab.image_output import write_image

                write_image(self.out / "images" / f"{label}-{st.label.replace(' ', '-')}.png", m["ldr"])
            # profile error against Monte Carlo and against the material's own model profile
            cells.update(refs.errors(st.technique, cells["model"], m["frame_plan"]))
        except Exception as exc:  # a failing technique is a row, not the end of the sweep
            cells.update(status="error", error=_first_line(exc))
        return LedgerRow(**cells), hdr, digest

    def scene_rows(
        self, sname: str, path, settings: list[Setting], ref_tech: str | None, peers, bar
    ) -> list[LedgerRow]:
        """Every setting's row on one scene (and the peers'), against its image reference and its truth."""
        from skinlab.scene.scenefile import load_scene

        label = scene_label(sname)
        scene = load_scene(path)
        refs = self.profile_references(scene, label)
        truth = self.load_truth(scene, label)
        tctx = self.truth_context(scene, label, truth) if truth is not None else None
        on_sheet = set(sheet_settings(settings))
        measured: dict[Setting, LedgerRow] = {}
        hdrs: dict[Setting, np.ndarray] = {}
        digests: dict[str, str] = {}
        for st in settings:
            self.say(f"{label}: {st.label}")
            row, hdr, digest = self.measure(scene, label, st, refs, tctx, st in on_sheet)
            measured[st] = row
            if hdr is not None:
                hdrs[st] = hdr
            if digest is not None:
                digests[st.label] = digest
            bar.update(1)
        ref_st = image_reference(settings, measured)
        rows = same_images(with_image_errors(measured, hdrs, ref_st, ref_tech), digests)
        if peers is not None:  # Blender's rows, against the same truth and image reference
            ref = hdrs.get(ref_st) if ref_st is not None else None
            mask = lit_mask(ref) if ref is not None else None
            prows, pmaps = peers.scene_rows(scene, label, self.sweep, truth, tctx, self.out, self.renderer, ref, mask,
                                            self.profiles.get(label), progress=self.say)  # fmt: skip
            rows += prows
            if pmaps:
                self.sheet.setdefault(label, {}).update(pmaps)
        return rows

    def meta(self, scenes, peer_res, peers, t_start: float, sweep_s: float, load_start, command) -> dict:
        """ledger.json's and ledger.md's run metadata."""
        sw = self.sweep
        truth = None
        if sw.truth is not None:
            truth = {"size": list(sw.truth.size), "spp": sw.truth.spp, "passes": sw.truth.passes,
                     "supersample": sw.truth.supersample, "missing": self.truth_notes, "quiet": self.truth_quiet,
                     "scenes": self.truth_scenes}  # fmt: skip
        return {
            "sweep": sw.name,
            "gl": self.gl,
            "cpus": os.cpu_count(),
            "size": list(sw.size),
            "shadow_size": sw.shadow_size,
            "warmup": sw.warmup,
            "frames": sw.frames,
            "budget_s": sw.budget_s,
            "photons": sw.photons,
            "scenes": [scene_label(s) for s in scenes],
            "truth": truth,
            "sweep_s": sweep_s,
            "total_s": time.perf_counter() - t_start,
            "peer": peer_res,
            "blender": None if peers is None else peers.meta,
            "loadavg_start": load_start,
            "loadavg_end": load_average(),
            "command": command,
            "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        }


def pyrender_peer(sweep: Sweep) -> dict:
    """The pyrender peer's frame times at the sweep's size (or why it failed)."""
    try:
        from skinlab.bench.peer import peer_bench

        return peer_bench(sweep.size, sweep.peer_frames)
    except Exception as exc:
        return {"error": _first_line(exc)}


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

    from .sweep import reference_technique

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = tuple(scenes or sweep.scenes)
    paths = {s: resolve_scene(s) for s in scenes}
    settings = sweep_settings(sweep)
    t_start, load_start = time.perf_counter(), load_average()
    bar = tqdm(total=len(settings) * len(scenes), file=sys.stderr, unit="setting", disable=not progress,
               desc="ledger", dynamic_ncols=True)  # fmt: skip
    run = LedgerRun(sweep, out, images, references, progress, bar.set_postfix_str)
    peers = None
    if blender:
        from .blender_peer import LedgerPeers

        peers = LedgerPeers(sweep.name, None if blender is True else tuple(blender))
    rows: list[LedgerRow] = []
    try:
        for sname in scenes:
            rows += run.scene_rows(sname, paths[sname], settings, reference_technique(), peers, bar)
    finally:
        bar.close()
        run.renderer.release()
        if peers is not None:
            peers.close()
    sweep_s = time.perf_counter() - t_start
    if run.sheet:
        error_map_sheet(
            run.sheet,
            out / "error_maps.png",
            "signed relative difference against the path-traced truth per pixel (red: brighter, blue: darker)",
        )
    peer_res = pyrender_peer(sweep) if peer else None
    meta = run.meta(scenes, peer_res, peers, t_start, sweep_s, load_start, command)
    return write_ledger(rows, meta, out, sweep, run.profiles)
