"""`skinlab bench startup`: how long a command takes to answer, and where the time goes.

Each run is a fresh process doing what ``skinlab render SCENE --size WxH --out x.png`` does, timed
phase by phase from inside (:func:`child`) and as a whole from outside (wall time, interpreter start
included):

- ``imports``: the command line's modules and its parser (every command module, the registry);
- ``scene``: reading the scene file, its meshes and textures;
- ``gl``: the headless EGL context and the renderer;
- ``plan``: planning the first frame (profile fits, tables, interreflection rays, UV seams: the work
  skinlab/cache.py keeps on disk);
- ``frame``: the frame `render` renders without ``--time``: every pass, shader compiles and texture
  uploads included, and its read-back;
- ``write``: the PNG.

Three starts per round, in a temporary folder: ``fresh`` as on a new machine (Skinlab's cache and
Mesa's shader cache both empty), ``cold`` with Skinlab's cache emptied again but Mesa's compiled
shaders kept (a first run on a machine that has run Skinlab before, or after Skinlab's code changed),
``warm`` with both kept (every later run). The caches each run
built or found are counted (``skinlab.cache.BUILT`` / ``LOADED``). Figures depend on the machine and
its load: the load average is reported with them.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from skinlab.bench.machine_load import load_average
from skinlab.declare import Field

KINDS = ("fresh", "cold", "warm")
PHASES = ("imports", "scene", "gl", "plan", "frame", "write")


# what the timed process runs: the command line's imports and parser first (as `skinlab render`
# does; the library itself never imports the command line), then child() for the rest
CHILD = """import time
t0 = time.perf_counter()
import json, skinlab.cli
skinlab.cli.build_parser("render")
t1 = time.perf_counter()
from skinlab.bench.startup import child
print(json.dumps(child({scene!r}, {size!r}, {out!r}, t0, t1)))
"""


def child(scene: str | None, size: tuple[int, int], out: str, t_start: float, t_imports: float) -> dict:
    """One start, timed phase by phase (in a fresh interpreter, after CHILD's imports)."""
    t = {"start": t_start, "imports": t_imports}
    from skinlab.scene.scenefile import load_scene

    sc = load_scene(scene)
    t["scene"] = time.perf_counter()
    from skinlab.gl.context import create_headless_context
    from skinlab.render.renderer import Renderer
    from skinlab.render.settings import RenderSettings

    renderer = Renderer(create_headless_context())
    settings = RenderSettings(*size)
    t["gl"] = time.perf_counter()
    renderer.plan(sc, settings)
    t["plan"] = time.perf_counter()
    result = renderer.render(sc, settings)
    t["frame"] = time.perf_counter()
    from skinlab.image_output import write_image

    write_image(Path(out), result.ldr)
    t["write"] = time.perf_counter()
    from skinlab.cache import BUILT, BUILT_S, LOADED

    keys = ["start", *PHASES]
    phases = {p: (t[p] - t[keys[i]]) * 1e3 for i, p in enumerate(keys[1:])}
    built_ms = {k: BUILT_S[k] * 1e3 for k in BUILT}
    return {"phases_ms": phases, "built": dict(BUILT), "built_ms": built_ms, "loaded": dict(LOADED)}


def _run_child(scene: str | None, size: tuple[int, int], env: dict, out: str) -> dict:
    code = CHILD.format(scene=scene, size=size, out=out)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=False)
    wall = (time.perf_counter() - t0) * 1e3
    if r.returncode != 0:
        last = (r.stderr.strip().splitlines() or ["(no output)"])[-1]
        raise RuntimeError(f"bench startup: the timed process failed: {last}")
    res = json.loads(r.stdout.strip().splitlines()[-1])
    res["wall_ms"] = wall
    return res


# rounds of starts (checked here; `skinlab bench startup --rounds`)
STARTUP_ROUNDS = Field(
    "rounds", "int", 3, (1, math.inf), doc="rounds of fresh, cold and warm starts; medians are shown"
)


def startup_bench(scene: str | None = None, size: tuple[int, int] = (64, 64), rounds: int = 3, progress=None) -> dict:
    """``rounds`` rounds of (fresh, cold, warm) starts (see the module docstring)."""
    STARTUP_ROUNDS.check(rounds, "--rounds")
    runs: dict[str, list[dict]] = {k: [] for k in KINDS}
    load_start = load_average()
    with tempfile.TemporaryDirectory(prefix="skinlab-startup-") as tmp:
        for i in range(rounds):
            cache, mesa = Path(tmp) / f"cache{i}", Path(tmp) / f"mesa{i}"
            env = dict(os.environ, SKINLAB_CACHE_DIR=str(cache), MESA_SHADER_CACHE_DIR=str(mesa))
            for kind in KINDS:
                if progress:
                    progress(f"round {i + 1}/{rounds}: {kind} start")
                if kind == "cold":
                    shutil.rmtree(cache, ignore_errors=True)
                runs[kind].append(_run_child(scene, size, env, str(Path(tmp) / "x.png")))
    out = {"scene": scene or "head", "size": list(size), "rounds": rounds, "cpu_count": os.cpu_count()}
    out["loadavg_start"], out["loadavg_end"] = load_start, load_average()
    # with PYTHONDONTWRITEBYTECODE set no .pyc is kept: every start compiles Skinlab's sources again
    out["bytecode_cached"] = not os.environ.get("PYTHONDONTWRITEBYTECODE")
    for kind, rs in runs.items():
        out[kind] = {
            "wall_ms": statistics.median(r["wall_ms"] for r in rs),
            "phases_ms": {p: statistics.median(r["phases_ms"][p] for r in rs) for p in PHASES},
            "built": rs[-1]["built"],
            "built_ms": {k: statistics.median(r["built_ms"].get(k, 0.0) for r in rs) for k in rs[-1]["built"]},
            "loaded": rs[-1]["loaded"],
        }
    return out


def report(res: dict) -> str:
    w, h = res["size"]
    lines = [
        f"skinlab render {res['scene']} --size {w}x{h}: median of {res['rounds']} fresh processes each; "
        f"load average {res['loadavg_start']} -> {res['loadavg_end']} on {res['cpu_count']} cores"
    ]
    if not res.get("bytecode_cached", True):
        lines.append("  (PYTHONDONTWRITEBYTECODE is set: no .pyc is kept, every start compiles the Python sources)")
    for kind in KINDS:
        r = res[kind]
        parts = ", ".join(f"{p} {r['phases_ms'][p]:.0f}" for p in PHASES)
        lines.append(
            f"  {kind:4s} {r['wall_ms'] / 1e3:6.2f} s wall   ({parts} ms; the rest is the interpreter's start)"
        )
        ms = r.get("built_ms", {})
        built = ", ".join(f"{k} {v} ({ms.get(k, 0.0):.0f} ms)" for k, v in sorted(r["built"].items())) or "nothing"
        loaded = ", ".join(f"{k} {v}" for k, v in sorted(r["loaded"].items())) or "nothing"
        lines.append(f"        computed (count, wall time, what it computes inside included): {built}")
        lines.append(f"        read from the cache: {loaded}")
    return "\n".join(lines)
