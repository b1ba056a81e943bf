"""Part of two one-off measurements, not a feature: measurement variants of a pass for the cost tools
(tools/forward_cost.py, tools/irradiance_cost.py), each declared where it lives: a shader library whose
expansions of one pass file carry defines its shaders declare for measuring only (``#ifdef
MEASURE_...``: a part of the pass taken out), checked to be read, so that a variant cannot silently time
the pass as shipped after the shader changed; a scene whose materials lack their maps (the passes then
compile without them)."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping

from skinlab.gl.shader_source import ShaderLibrary
from skinlab.render.technique import HOOK_INCLUDE, PLAIN_HOOK


def measure_library(
    pass_file: str, defines: Mapping[str, object], hook: str = PLAIN_HOOK, variant: Mapping[str, object] | None = None
) -> ShaderLibrary:
    """A ShaderLibrary adding `defines` to every expansion of `pass_file` (ShaderLibrary.defines);
    SystemExit naming the file and the define when the pass (its includes too, the forward pass
    with technique hook `hook` and the defines of `variant`) does not read one."""
    library = ShaderLibrary(defines={pass_file: dict(defines)})
    flat = ShaderLibrary().expand(pass_file, dict(variant or {}), aliases={HOOK_INCLUDE: hook}).flat
    for name in defines:
        if name not in flat:
            raise SystemExit(f"{pass_file}: no shader of the pass reads {name} any more; update this tool")
    return library


def without_maps(scene, maps: tuple[str, ...]):
    """`scene` (a freshly loaded one: changed in place) with `maps` taken out of its materials (the
    passes then compile without HAS_BASE_COLOR_MAP, HAS_NORMAL_MAP, ... and fetch none of them)."""
    for node in scene.mesh_nodes():
        node.material = node.material.with_overrides({k: None for k in maps})
    return scene


def finished_ms(ctx, run: Callable[..., object], *args) -> float:
    """Wall milliseconds of `run(*args)` with the GL work before it finished and its own waited for."""
    ctx.finish()
    t0 = time.perf_counter()
    run(*args)
    ctx.finish()
    return (time.perf_counter() - t0) * 1e3


def load_line(start: tuple[float, ...]) -> str:
    """The load average at the start and now, for the printout."""
    return f"load average {tuple(round(x, 2) for x in start)} -> {tuple(round(x, 2) for x in os.getloadavg())}"


def print_medians(times: Mapping[str, list[float]], width: int) -> None:
    """Each variant's median milliseconds and its share of the first variant's (the base)."""
    import statistics

    base = statistics.median(next(iter(times.values())))
    for name, v in times.items():
        m = statistics.median(v)
        print(f"  {name:<{width}} {m:8.1f} ms  ({m / base:5.0%} of base)")
