"""Shader hot-reload latency (`skinlab bench reload`): from saving a file to the first frame
rendered with the recompiled program, in the viewer's loop without a window."""

from __future__ import annotations

import math
import re
import statistics
import time
from pathlib import Path

from skinlab.declare import Field
from skinlab.render.settings import RenderSettings

# the benchmark's own parameters, declared once (checked here; `skinlab bench reload`'s options)
RELOAD_FIELDS = {
    f.name: f
    for f in (
        Field("repeats", "int", 10, (1, math.inf), doc="edits to time"),
        Field("file", "string", "passes/tonemap.frag", doc="shader file to edit, relative to shaders/"),
        Field("settle", "float", 0.05, (0.0, 10.0), unit="s", doc="ShaderWatcher settle time, as skinlab view's"),
        Field(
            "mode",
            "choice",
            "on-demand",
            choices=("on-demand", "continuous"),
            doc="on-demand: the viewer's default loop (idle polls at 60 Hz, a frame only after a change); "
            "continuous: a frame every iteration (as with skinlab view --continuous)",
        ),
        Field("timeout", "float", 20.0, (0.0, math.inf), lo_open=True, unit="s", doc="give up on one edit after this"),
    )
}
RELOAD_SHADOW_SIZE = 512  # the timed frames' shadow map: smaller than a render's, for a quick frame after an edit
RELOAD_TSD_SIZE = 256  # and their texture-space irradiance texels per side

_MAIN = re.compile(r"\bvoid\s+main\s*\(\s*(void)?\s*\)")
_OUT = re.compile(r"^\s*(?:layout\s*\([^)]*\)\s*)?out\s+vec4\s+(\w+)\s*;", re.M)


def bench_edit(text: str, i: int) -> tuple[str, bool]:
    """The i-th edit of a shader file and whether it must change the image.

    A fragment stage with one ``out vec4`` gets its ``main`` wrapped so the output is scaled by
    0.5 or 0.75 (alternating: every edit changes the image); any other file gets a comment
    appended, which recompiles the programs that include it without changing pixels."""
    outs = _OUT.findall(text)
    if len(outs) == 1 and len(_MAIN.findall(text)) == 1:
        factor = 0.5 if i % 2 == 0 else 0.75
        body = _MAIN.sub("void skinlab_bench_main()", text, count=1)
        return (
            body + f"\n// skinlab bench reload edit {i}\nvoid main() {{\n    skinlab_bench_main();\n"
            f"    {outs[0]}.rgb *= {factor};\n}}\n"
        ), True
    return text + f"\n// skinlab bench reload edit {i}\n", False


def _stats(values: list[float]) -> dict:
    return {
        "median": statistics.median(values),
        "max": max(values),
        "min": min(values),
        "samples": [round(v, 3) for v in values],
    }


def reload_bench(
    size=(128, 128),
    repeats: int = 10,
    file: str = "passes/tonemap.frag",
    settle_s: float = 0.05,
    shadow_size: int = RELOAD_SHADOW_SIZE,
    tsd_size: int = RELOAD_TSD_SIZE,
    timeout_s: float = 20.0,
    mode: str = "on-demand",
) -> dict:
    """Copy shaders/ to a temporary folder, render the head continuously with a Renderer on it
    while a ShaderWatcher watches the copy, write an edited ``file`` ``repeats`` times and time
    each write until the end of the first frame (tone-mapped pixels read back) whose programs
    were recompiled from it; where the edit changes the image, that frame's pixels must differ
    from the previous frame's. This is the viewer's loop without a window: ``on-demand`` polls
    at 60 Hz while idle and renders once a reload was applied (the viewer's default);
    ``continuous`` renders a frame every iteration, so a save usually waits for the frame in
    flight before it is even polled."""
    import shutil
    import tempfile

    import numpy as np

    from skinlab.gl.context import create_headless_context, describe
    from skinlab.gl.hot_reload import ShaderWatcher
    from skinlab.gl.shader_source import SHADER_ROOT, ShaderError, ShaderLibrary
    from skinlab.render.renderer import Renderer
    from skinlab.scene.scenefile import load_scene

    for name, value in (("repeats", repeats), ("mode", mode), ("settle", settle_s), ("timeout", timeout_s)):
        RELOAD_FIELDS[name].check(value, f"--{name}")
    w, h = size
    from skinlab.render.techniques.tsd import TsdSettings

    settings = RenderSettings(w, h, shadow_size=shadow_size, technique=TsdSettings(size=tsd_size))
    ctx = create_headless_context()
    scene = load_scene(None)
    with tempfile.TemporaryDirectory(prefix="skinlab-reload-") as tmp:
        root = Path(tmp) / "shaders"
        shutil.copytree(SHADER_ROOT, root)
        target = (root / file).resolve()
        if root.resolve() not in target.parents or not target.is_file():
            raise ValueError(f"--file: no shader file {file!r} under {SHADER_ROOT}")
        renderer = Renderer(ctx, ShaderLibrary(root=root))
        watcher = ShaderWatcher(renderer.programs, root, settle_s=settle_s)
        try:
            prev = renderer.render(scene, settings, readback=("ldr",)).ldr  # compile everything once
            keys = renderer.programs.dependents({target})
            if not keys:
                raise ValueError(f"--file: no program of the head's frame includes {file}")
            original = target.read_text(encoding="utf-8")
            latency, reload_ms, compile_ms, frame_ms, frames_waited = [], [], [], [], []
            image_check = bench_edit(original, 0)[1]
            for i in range(repeats):
                # let late events of the previous write settle, so each edit starts from quiet
                t_quiet = time.perf_counter()
                while time.perf_counter() - t_quiet < max(3 * settle_s, 0.1):
                    if watcher.poll() is not None:
                        prev = renderer.render(scene, settings, readback=("ldr",)).ldr
                    time.sleep(0.005)
                gens = {k: renderer.programs.entries[k].generation for k in keys}
                text, _ = bench_edit(original, i)
                t0 = time.perf_counter()
                target.write_text(text, encoding="utf-8")
                t_reload, t_compile, n = None, None, 0
                while True:
                    tp = time.perf_counter()
                    errors = watcher.poll()
                    if errors is not None:
                        if errors:
                            raise ShaderError(f"bench edit {i} of {file} did not compile: {errors[0]}")
                        t_reload = time.perf_counter()
                        t_compile = t_reload - tp
                    elif mode == "on-demand":
                        if time.perf_counter() - t0 > timeout_s:
                            raise RuntimeError(f"no reload of {file} within {timeout_s} s of writing it")
                        time.sleep(1 / 60)
                        continue
                    tf0 = time.perf_counter()
                    res = renderer.render(scene, settings, readback=("ldr",))
                    t_end = time.perf_counter()
                    n += 1
                    if all(renderer.programs.entries[k].generation > g for k, g in gens.items()):
                        break
                    if t_end - t0 > timeout_s:
                        raise RuntimeError(f"no reload of {file} within {timeout_s} s of writing it")
                if image_check and np.array_equal(res.ldr, prev):
                    raise RuntimeError(f"edit {i} of {file} was recompiled but the frame did not change")
                prev = res.ldr
                latency.append((t_end - t0) * 1e3)
                reload_ms.append((t_reload - t0) * 1e3 if t_reload is not None else float("nan"))
                compile_ms.append(t_compile * 1e3 if t_compile is not None else float("nan"))
                frame_ms.append((t_end - tf0) * 1e3)
                frames_waited.append(n)
        finally:
            watcher.stop()
            renderer.release()
    return {
        "gl": describe(ctx),
        "mode": mode,
        "size": [w, h],
        "file": file,
        "programs": len(keys),
        "repeats": repeats,
        "settle_s": settle_s,
        "check": "image changed" if image_check else "program recompiled",
        "latency_ms": _stats(latency),
        "reload_applied_ms": _stats(reload_ms),
        "recompile_ms": _stats(compile_ms),
        "first_frame_ms": _stats(frame_ms),
        "frames_until_new": frames_waited,
    }
