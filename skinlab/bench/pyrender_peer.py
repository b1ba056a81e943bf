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


def _setup(spec: dict):
    """pyrender's scene and offscreen renderer for a spec (in the child process)."""
    os.environ["PYOPENGL_PLATFORM"] = "egl"
    import pyrender
    import trimesh

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
    return pyrender.OffscreenRenderer(w, h), scene


def _child(spec_path: str, out_path: str) -> None:
    import time

    spec = json.loads(Path(spec_path).read_text())
    r, scene = _setup(spec)
    color, depth = r.render(scene)
    times = []
    for _ in range(spec.get("frames", 0)):
        t0 = time.perf_counter()
        r.render(scene)  # includes the read-back, as pyrender always reads back
        times.append((time.perf_counter() - t0) * 1e3)
    np.savez(out_path, color=color, depth=depth, times=np.array(times))
    r.delete()


def _serve(spec_path: str) -> None:
    """The child of PeerSession: set up, render once, answer 'ready'; then per line 'N' on stdin time
    N frames and answer their times (JSON, ms); an empty line or EOF ends it."""
    import sys
    import time

    r, scene = _setup(json.loads(Path(spec_path).read_text()))
    r.render(scene)
    out = sys.stdout
    out.write("ready\n")
    out.flush()
    for line in sys.stdin:
        if not line.strip():
            break
        times = []
        for _ in range(int(line)):
            t0 = time.perf_counter()
            r.render(scene)
            times.append((time.perf_counter() - t0) * 1e3)
        out.write(json.dumps(times) + "\n")
        out.flush()
    r.delete()


def _spec(meshes, camera_pose, yfov, znear, zfar, size, frames=0) -> dict:
    return {
        "meshes": [{"file": str(f), "matrix": np.asarray(m).tolist()} for f, m in meshes],
        "camera_pose": np.asarray(camera_pose).tolist(),
        "yfov": yfov,
        "znear": znear,
        "zfar": zfar,
        "size": list(size),
        "frames": frames,
    }


def _child_command(call: str) -> list[str]:
    root = str(Path(__file__).resolve().parents[2])  # the folder that holds the skinlab package
    return [
        sys.executable,
        "-c",
        f"import sys; sys.path.insert(0, {root!r}); from skinlab.bench.pyrender_peer import {call}",
    ]


class PeerSession:
    """pyrender kept alive in a child process, so that its frames can be timed in rounds between
    Skinlab's (interleaved: a change of machine load hits both alike). Use as a context manager."""

    def __init__(self, meshes, camera_pose, yfov, znear, zfar, size, timeout: float = 600):
        self._tmp = tempfile.TemporaryDirectory(prefix="skinlab-peer-")
        sp = Path(self._tmp.name) / "spec.json"
        sp.write_text(json.dumps(_spec(meshes, camera_pose, yfov, znear, zfar, size)))
        env = dict(os.environ, PYOPENGL_PLATFORM="egl")
        self._proc = subprocess.Popen(
            _child_command(f"_serve; _serve({str(sp)!r})"),
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        self._read()  # "ready"

    def _read(self) -> str:
        line = self._proc.stdout.readline()
        if not line:
            err = self._proc.stderr.read()
            self.close()
            raise RuntimeError(f"pyrender peer failed (exit {self._proc.poll()}):\n{err[-2000:]}")
        return line

    def time_frames(self, n: int) -> list[float]:
        """Render and time n frames (ms each, read-back included)."""
        self._proc.stdin.write(f"{int(n)}\n")
        self._proc.stdin.flush()
        return [float(x) for x in json.loads(self._read())]

    def close(self) -> None:
        if self._proc.poll() is None:
            try:
                self._proc.stdin.write("\n")
                self._proc.stdin.flush()
                self._proc.wait(timeout=30)
            except (OSError, subprocess.TimeoutExpired):
                self._proc.kill()
                self._proc.wait()
        for f in (self._proc.stdin, self._proc.stdout, self._proc.stderr):
            f.close()
        self._tmp.cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


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
        sp, op = Path(tmp) / "spec.json", Path(tmp) / "out.npz"
        sp.write_text(json.dumps(_spec(meshes, camera_pose, yfov, znear, zfar, size, frames)))
        env = dict(os.environ, PYOPENGL_PLATFORM="egl")
        cmd = _child_command(f"_child; _child({str(sp)!r}, {str(op)!r})")
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
        if proc.returncode != 0:
            raise RuntimeError(f"pyrender peer failed (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
        data = np.load(op)
        return {k: data[k] for k in data.files}
