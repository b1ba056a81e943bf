"""pyrender as an independent peer: same mesh, camera and size, rendered by another renderer.

pyrender creates its own EGL context and makes it current, which would pull the GL state from
under moderngl in the same process, so the peer always runs in a child process
(:func:`run_peer`). The child loads the mesh with trimesh itself and takes the camera as plain
matrices, so the only things shared with Skinlab are the file and the numbers.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np


def _child(spec_path: str, out_path: str) -> None:
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    import time

    import pyrender
    import trimesh

    spec = json.loads(Path(spec_path).read_text())
    w, h = spec["size"]
    scene = pyrender.Scene(bg_color=[0, 0, 0, 0], ambient_light=[0.05, 0.05, 0.05])
    for item in spec["meshes"]:
        tm = trimesh.load(item["file"], force="mesh", process=False)
        mesh = pyrender.Mesh.from_trimesh(tm, smooth=True)
        scene.add(mesh, pose=np.array(item["matrix"]))
    cam = pyrender.PerspectiveCamera(yfov=spec["yfov"], aspectRatio=w / h, znear=spec["znear"], zfar=spec["zfar"])
    scene.add(cam, pose=np.array(spec["camera_pose"]))
    light = pyrender.DirectionalLight(color=np.ones(3), intensity=3.0)
    scene.add(light, pose=np.array(spec["camera_pose"]))
    r = pyrender.OffscreenRenderer(w, h)
    color, depth = r.render(scene)
    times = []
    for _ in range(spec.get("frames", 0)):
        t0 = time.perf_counter()
        r.render(scene)  # includes the read-back, as pyrender always reads back
        times.append((time.perf_counter() - t0) * 1e3)
    np.savez(out_path, color=color, depth=depth, times=np.array(times))
    r.delete()


def run_peer(
    meshes: list[tuple[str, np.ndarray]],
    camera_pose: np.ndarray,
    yfov: float,
    znear: float,
    zfar: float,
    size: tuple[int, int],
    frames: int = 0,
    timeout: float = 600,
) -> dict:
    """Render with pyrender in a subprocess; returns color (H,W,3), depth (H,W; 0 = background),
    and per-frame times in ms if ``frames`` > 0."""
    with tempfile.TemporaryDirectory(prefix="skinlab-peer-") as tmp:
        spec = {
            "meshes": [{"file": str(f), "matrix": np.asarray(m).tolist()} for f, m in meshes],
            "camera_pose": np.asarray(camera_pose).tolist(),
            "yfov": yfov,
            "znear": znear,
            "zfar": zfar,
            "size": list(size),
            "frames": frames,
        }
        sp, op = Path(tmp) / "spec.json", Path(tmp) / "out.npz"
        sp.write_text(json.dumps(spec))
        code = (
            f"import sys; sys.path.insert(0, {str(Path(__file__).resolve().parents[2])!r}); "
            f"from app.bench.pyrender_peer import _child; _child({str(sp)!r}, {str(op)!r})"
        )
        env = dict(os.environ, PYOPENGL_PLATFORM="egl")
        proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout, env=env)
        if proc.returncode != 0:
            raise RuntimeError(f"pyrender peer failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
        data = np.load(op)
        return {k: data[k] for k in data.files}
