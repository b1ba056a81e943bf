"""Timing one ledger setting: warm-up frames, then the median and percentiles of the frame time (GPU
timer queries where the GPU has them, else wall time with glFinish after each pass)."""

from __future__ import annotations

import statistics
import time

from .image_error import percentile


def _clock(timings) -> str:
    if not timings.software_gl and timings.passes and all(p.gpu_ms is not None for p in timings.passes):
        return "gpu-timer"
    return "cpu-synchronised"


def measure_setting(renderer, scene, rs, warmup: int, frames: int, budget_s: float) -> dict:
    """Warm up, time `frames` frames (fewer, at least 3, if they would take over budget_s), then one
    frame with HDR and LDR read back. ``technique_ms_median``: the median over frames of the sum of
    the technique's own passes (the kinds it registers); ``blur_levels``: how many passes of the kind
    its LedgerStyle.levels names the frame planned (0 where it names none)."""
    from skinlab.render.registry import get_technique

    tech = get_technique(rs.technique_name)
    t_warm = 0.0
    for _ in range(max(warmup, 1)):
        t0 = time.perf_counter()
        renderer.render(scene, rs, readback=False)
        t_warm = time.perf_counter() - t0
    n = frames
    if t_warm * frames > budget_s:
        n = max(min(3, frames), int(budget_s / max(t_warm, 1e-9)))
    fm, wall, own_ms, passes, clocks = [], [], [], {}, set()
    for _ in range(n):
        res = renderer.render(scene, rs, readback=False)
        fm.append(res.timings.frame_ms)
        wall.append(res.cpu_ms)
        clock = _clock(res.timings)
        clocks.add(clock)
        own = {p.name for p in res.plan.passes if p.kind in tech.passes}
        t_own = 0.0
        for p in res.timings.passes:
            v = p.gpu_ms if clock == "gpu-timer" else p.cpu_ms
            passes.setdefault(p.name, []).append(v)
            if p.name in own:
                t_own += v
        own_ms.append(t_own)
    final = renderer.render(scene, rs, readback=("hdr", "ldr"))
    levels = sum(1 for p in final.plan.passes if tech.ledger.levels and p.kind == tech.ledger.levels)
    pm = {k: statistics.median(v) for k, v in passes.items()}
    return {
        "frames": n,
        "frame_ms_median": statistics.median(fm),
        "frame_ms_p10": percentile(fm, 10),
        "frame_ms_p90": percentile(fm, 90),
        "wall_ms_median": statistics.median(wall),
        "technique_ms_median": statistics.median(own_ms),
        "clock": "+".join(sorted(clocks)),
        "passes": pm,
        "blur_levels": levels,
        "hdr": final.hdr,
        "ldr": final.ldr,
        "plan": final.plan.names(),
        "kinds": [p.kind for p in final.plan.passes],
        "frame_plan": final.plan,
    }
