"""Blender's EEVEE and Cycles as peers in the accuracy ledger (`skinlab bench accuracy --blender`,
`skinlab bench peer --blender`): the same scene (skinlab/bench/blender_scene.py) rendered by Blender
in a child process (skinlab/bench/blender_child.py: why a child, there), in the same run as
Skinlab's techniques, as ledger rows against the same path-traced truth.

Rows (:data:`PEER_SETTINGS`):

* ``eevee 1 spp``: EEVEE (Blender 5's EEVEE Next) at one sample per render, the realtime
  comparison; compared with the truth at N x the truth's size box-filtered, exactly as Skinlab's
  frames are (``TruthSpec.supersample``);
* ``eevee 64 spp``: EEVEE at its default sample count (its own antialiasing: the truth-size frame
  is rendered at the truth's size);
* ``cycles rw N spp`` / ``cycles rw-skin N spp``: Cycles on the CPU, Principled BSDF subsurface
  method Random Walk / Random Walk (Skin), N samples per pixel, no denoising, no clamping, box
  pixel filter; the frame compared with the truth is the mean of two renders of N/2 samples with
  different seeds, whose difference is the frame's own noise floor (``peer_noise``, ``peer_noise_block``:
  the truth's convention).

Time: each render is ``bpy.ops.render.render`` in the child, wall time; the first render of a scene
(EEVEE: shader compilation; Cycles: kernel loading, BVH) is reported apart (``first_frame_ms``),
then one more untimed, then up to ``frames`` timed at the ledger's size. An EEVEE render does
per render what a viewport would keep (scene sync, the shadow pool's clear): ``docs/ground-truth.md``
gives its time per sample beside it.

The truth metrics come from the ledger's own functions (skinlab/bench/truth_ledger.py
``truth_errors``, ``write_error_map``), so the rows carry every column Skinlab's rows do.
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .ledger_row import LedgerRow

CHILD = Path(__file__).with_name("blender_child.py")
PYTHON_ENV = "SKINLAB_BLENDER_PYTHON"  # the Python with bpy that runs the child
VENV = ".venv-blender"  # where `make test` / `make bench` install pyproject's [peers] extra
PEER_TECHNIQUES = ("blender-eevee", "blender-cycles")
# the ledger's plots draw peer rows with these (Skinlab's techniques use their LedgerStyle)
PEER_STYLES = {"blender-eevee": ("P", "tab:olive"), "blender-cycles": ("X", "black")}


class BlenderUnavailable(RuntimeError):
    """Blender (bpy) cannot be run here; the message is one line saying why and what to do."""


def blender_python() -> str:
    """The interpreter with bpy: $SKINLAB_BLENDER_PYTHON, this one if it has bpy, else the repository's
    .venv-blender (made by `make test`); BlenderUnavailable when none is there."""
    env = os.environ.get(PYTHON_ENV)
    if env:
        if not Path(env).is_file():
            raise BlenderUnavailable(f"{PYTHON_ENV}={env}: no such file (expected a Python with bpy 5.0)")
        return env
    import importlib.util

    if importlib.util.find_spec("bpy") is not None:
        return sys.executable
    for root in (Path(__file__).resolve().parents[2], Path.cwd()):
        p = root / VENV / "bin" / "python"
        if p.is_file():
            return str(p)
    raise BlenderUnavailable(
        "Blender's bpy is not installed: `make test` or `make bench` installs pyproject's [peers] extra "
        f"(bpy 5.0.1, CPython 3.11 only) into {VENV}; or set {PYTHON_ENV} to a Python that has bpy"
    )


class BlenderSession:
    """Blender kept alive in a child process (import once, compile shaders once per scene). Use as a
    context manager."""

    def __init__(self, timeout: float = 900.0):
        py = blender_python()
        self._tmp = tempfile.TemporaryDirectory(prefix="skinlab-blender-")
        self.dir = Path(self._tmp.name)
        self._log = open(self.dir / "blender.log", "w+")
        self.timeout = timeout
        self._n = 0
        self._proc = subprocess.Popen(
            [py, str(CHILD)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._log, text=True
        )
        ready = self._reply("starting")
        self.version = ready.get("version", "?")
        self.import_ms = ready.get("import_ms", math.nan)

    def _tail(self) -> str:
        self._log.flush()
        self._log.seek(0)
        lines = [x for x in self._log.read().splitlines() if x.strip()]
        return lines[-1] if lines else "(no output)"

    def _reply(self, what: str) -> dict:
        line = self._proc.stdout.readline()
        if not line:
            code = self._proc.wait(timeout=30)
            msg = f"Blender child ended while {what} (exit {code}): {self._tail()}"
            self.close()
            raise BlenderUnavailable(msg) if what == "starting" else RuntimeError(msg)
        return json.loads(line)

    def request(self, **req) -> dict:
        self._proc.stdin.write(json.dumps(req) + "\n")
        self._proc.stdin.flush()
        rep = self._reply(req.get("cmd", "?"))
        if not rep.get("ok", False):
            raise RuntimeError(f"Blender {req.get('cmd')}: {rep.get('error')}")
        return rep

    def load(self, spec) -> dict:
        from .blender_scene import save_spec

        self._n += 1
        path = save_spec(spec, self.dir / f"spec{self._n}.npz")
        self.spec = spec
        return self.request(cmd="load", spec=str(path))

    def readback(self) -> tuple[dict, dict]:
        out = self.dir / "readback.npz"
        self.request(cmd="readback", out=str(out))
        with np.load(out) as z:
            info = json.loads(bytes(z["header"]).decode())
            return info, {k: z[k] for k in z.files if k != "header"}

    def render(
        self,
        engine: str,
        spp: int,
        size=None,
        frames: int = 0,
        image: bool = True,
        method: str = "RANDOM_WALK",
        seed: int = 0,
    ) -> tuple[np.ndarray | None, dict]:
        """(linear RGBA image or None, the child's reply with image_ms and frames_ms)."""
        from skinlab.image_output import read_image

        self._n += 1
        path = self.dir / f"frame{self._n}.exr" if image else None
        rep = self.request(
            cmd="render",
            engine=engine,
            spp=int(spp),
            size=list(size) if size else None,
            frames=int(frames),
            image=str(path) if path else None,
            method=method,
            seed=int(seed),
        )
        img = None
        if path is not None:
            img = read_image(path).astype(np.float32)
            path.unlink()
        return img, rep

    def close(self) -> None:
        if self._proc.poll() is None:
            try:
                self._proc.stdin.write(json.dumps({"cmd": "quit"}) + "\n")
                self._proc.stdin.flush()
                self._proc.wait(timeout=60)
            except (OSError, subprocess.TimeoutExpired):
                self._proc.kill()
                self._proc.wait()
        for f in (self._proc.stdin, self._proc.stdout):
            f.close()
        self._log.close()
        self._tmp.cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def box_filter(img: np.ndarray, n: int) -> np.ndarray:
    """Mean over n x n pixel tiles (an image rendered at n x the size, as Skinlab's supersampling)."""
    if n == 1:
        return img
    h, w = img.shape[0] // n, img.shape[1] // n
    return img[: h * n, : w * n].reshape(h, n, w, n, img.shape[2]).mean(axis=(1, 3))


@dataclass(frozen=True)
class PeerSetting:
    engine: str  # eevee | cycles
    spp: int
    method: str = "RANDOM_WALK"  # Cycles' subsurface method (EEVEE reads the same radius)
    # frames timed at the ledger's size; False: the time is that of the frame compared with the truth, at the
    # truth's size (the row's width and height say so), for renders too slow to repeat on 2 cores
    timed: bool = True

    @property
    def technique(self) -> str:
        return f"blender-{self.engine}"

    @property
    def label(self) -> str:
        if self.engine == "eevee":
            return f"eevee {self.spp} spp"
        return f"cycles {'rw-skin' if self.method == 'RANDOM_WALK_SKIN' else 'rw'} {self.spp} spp"


EEVEE_DEFAULT_SPP = 64  # EEVEE's taa_render_samples default (Blender 5.0)
PEER_SETTINGS = {
    "quick": (
        PeerSetting("eevee", 1),
        PeerSetting("eevee", EEVEE_DEFAULT_SPP, timed=False),
        PeerSetting("cycles", 64, timed=False),
        PeerSetting("cycles", 64, "RANDOM_WALK_SKIN", timed=False),
    ),
    "tiny": (PeerSetting("eevee", 1), PeerSetting("cycles", 4)),
    # Cycles as a second truth (docs/ground-truth.md): many samples, only the frame compared with the truth
    "cycles-truth": (PeerSetting("cycles", 1024, timed=False), PeerSetting("cycles", 1024, "RANDOM_WALK_SKIN", False)),
}
PEER_SETTINGS["full"] = PEER_SETTINGS["quick"]


def _noise(a: np.ndarray, b: np.ndarray, ref: np.ndarray) -> dict:
    from skinlab.truth.compare import image_error, object_mask

    e = image_error(a, b, object_mask(ref))
    return {"peer_noise": e["rel_l1"], "peer_noise_block": e["rel_l1_block"]}


def peer_rows(
    session: BlenderSession,
    scene,
    label: str,
    sweep,
    truth,
    tctx,
    out: Path,
    settings,
    frames: int,
    budget_s: float,
    progress=None,
    profiles: dict | None = None,
) -> tuple[list[LedgerRow], dict[str, np.ndarray], dict]:
    """The peer rows of one scene: (rows, {setting label: frame at the ledger's size}, error maps
    {label: signed difference against the truth}). The session renders `scene` built at the ledger's
    size; every row has the ledger's truth columns (truth_ledger.truth_errors against `tctx`, the
    scene's TruthContext) when `truth` is given; a declared profile goes into `profiles[label]`."""
    from skinlab.truth.metrics import relative_map

    from .blender_scene import blender_spec
    from .truth_ledger import truth_errors, write_error_map, write_flip_map

    w, h = sweep.size
    session.load(blender_spec(scene, w, h))
    rows, frames_at_size, maps = [], {}, {}
    first: dict[str, float] = {}
    for st in settings:
        if progress:
            progress(f"{label}: {st.label}")
        row: dict = {"scene": label, "setting": st.label, "technique": st.technique, "width": w, "height": h,
                     "peer": True, "samples": st.spp, "clock": "wall"}  # fmt: skip
        try:
            if st.timed:
                img, rep = session.render(st.engine, st.spp, (w, h), frames=0, method=st.method)
                warm = 0
                if st.engine not in first:  # the scene's first render on this engine: compilation, BVH
                    first[st.engine] = row["first_frame_ms"] = rep["image_ms"]
                    warm = 1  # one more untimed
                else:  # the image's render was the warm-up
                    row["first_frame_ms"] = math.nan
                one = rep["image_ms"]
                n = max(2, min(frames, int(budget_s * 1e3 / max(one, 1e-3))))
                _, rep = session.render(st.engine, st.spp, (w, h), frames=n + warm, image=False, method=st.method)
                times = rep["frames_ms"][warm:]
                row.update(
                    frames=len(times),
                    frame_ms_median=statistics.median(times),
                    frame_ms_p10=float(np.percentile(times, 10)),
                    frame_ms_p90=float(np.percentile(times, 90)),
                    wall_ms_median=statistics.median(times),
                )
                frames_at_size[st.label] = img
            if truth is not None:
                tw, th = truth.image.shape[1], truth.image.shape[0]
                if st.engine == "cycles":
                    a, ra = session.render("cycles", max(st.spp // 2, 1), (tw, th), method=st.method, seed=1)
                    b, rb = session.render("cycles", max(st.spp // 2, 1), (tw, th), method=st.method, seed=2)
                    small = 0.5 * (a + b)
                    row.update(_noise(a, b, truth.image))
                    row["truth_frame_ms"] = ra["image_ms"] + rb["image_ms"]
                else:
                    ss = sweep.truth.supersample if st.spp == 1 else 1
                    big, rep = session.render("eevee", st.spp, (tw * ss, th * ss), method=st.method)
                    small = box_filter(big, ss)
                    row["truth_frame_ms"] = rep["image_ms"]
                got = truth_errors(small, tctx)
                prof = got.pop("profile", None)
                if prof is not None and profiles is not None:
                    profiles[st.label] = prof
                row.update(got)
                if not st.timed:
                    row.update(
                        frames=1,
                        frame_ms_median=row["truth_frame_ms"],
                        wall_ms_median=row["truth_frame_ms"],
                        width=tw,
                        height=th,
                    )
                safe = st.label.replace(" ", "-")
                write_error_map(out / "error_maps" / f"{label}-{safe}.png", small, truth)
                write_flip_map(out / "flip_maps" / f"{label}-{safe}.png", small, tctx)
                maps[st.label] = relative_map(small, truth.image)
        except Exception as exc:  # a peer that fails is a row, as a technique that fails
            row["status"] = "error"
            row["error"] = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
        rows.append(LedgerRow(**row))
    return rows, frames_at_size, maps


def interleaved_ratio(
    session: BlenderSession, renderer, scene, rs, spp: int = 1, rounds: int = 3, frames: int = 3
) -> dict:
    """Skinlab's frame (`rs`, HDR read back: the work done) against EEVEE at `spp` samples on the same
    scene (already loaded in `session` at rs's size), in interleaved rounds so that a change of the
    machine's load hits both alike: {"skinlab_ms", "eevee_ms", "ratio" (median of the rounds'
    skinlab / eevee), "per_round"}."""
    size = (rs.width, rs.height)
    renderer.render(scene, rs, readback=("hdr",))
    session.render("eevee", spp, size, frames=1, image=False)
    sk, ee, per = [], [], []
    for _ in range(rounds):
        mine = []
        for _ in range(frames):
            t0 = time.perf_counter()
            renderer.render(scene, rs, readback=("hdr",))
            mine.append((time.perf_counter() - t0) * 1e3)
        theirs = session.render("eevee", spp, size, frames=frames, image=False)[1]["frames_ms"]
        sk += mine
        ee += theirs
        per.append(statistics.median(mine) / statistics.median(theirs))
    return {
        "skinlab_ms": statistics.median(sk),
        "eevee_ms": statistics.median(ee),
        "ratio": statistics.median(per),
        "per_round": per,
        "eevee_spp": spp,
        "size": list(size),
    }


RATIO_ROUNDS = {"tiny": {"rounds": 1, "frames": 1}}  # the tests' sweep: one round of one frame each


def default_setting():
    """The ledger Setting of Skinlab's default frame (the default technique at its default settings)."""
    from skinlab.render.settings import RenderSettings

    from .sweep import Setting

    return Setting.of(RenderSettings(8, 8).technique_name)


class LedgerPeers:
    """The Blender peers of one ledger run: the child session, the settings, the per-scene rows and
    the interleaved frame-time ratio against Skinlab's default frame; ``meta`` for ledger.json."""

    def __init__(self, sweep_name: str, settings: tuple | None = None):
        self.settings = settings or PEER_SETTINGS.get(sweep_name, PEER_SETTINGS["quick"])
        self.meta: dict = {"settings": [s.label for s in self.settings], "ratios": {}}
        try:
            self.session = BlenderSession()
            self.meta.update(version=self.session.version, import_ms=self.session.import_ms)
        except BlenderUnavailable as exc:
            self.session = None
            self.meta["error"] = str(exc)
            print(f"skinlab bench: the Blender peers are skipped: {exc}", file=sys.stderr)

    def scene_rows(self, scene, label, sweep, truth, tctx, out, renderer, ref, mask, profiles=None, progress=None):
        """(rows, error maps) of `scene`; the rows also get the image error against the ledger's
        image reference `ref` (at the ledger's size) where it exists."""
        from .image_error import image_error

        if self.session is None:
            return [], {}
        rows, at_size, maps = peer_rows(
            self.session, scene, label, sweep, truth, tctx, out, self.settings, sweep.frames, sweep.budget_s * 10,
            progress, profiles,
        )  # fmt: skip
        if ref is not None:
            rows = [r.but(**image_error(at_size[r.setting], ref, mask)) if r.setting in at_size else r for r in rows]
        if any(s.engine == "eevee" and s.spp == 1 for s in self.settings):
            try:
                rs = default_setting().render_settings(sweep)
                self.meta["ratios"][label] = {
                    "skinlab_setting": default_setting().label,
                    **interleaved_ratio(self.session, renderer, scene, rs, **RATIO_ROUNDS.get(sweep.name, {})),
                }
            except Exception as exc:
                self.meta["ratios"][label] = {"error": f"{type(exc).__name__}: {exc}".splitlines()[0][:300]}
        return rows, maps

    def close(self):
        if self.session is not None:
            self.session.close()


def _pct(v) -> str:
    return "" if not isinstance(v, (int, float)) or not math.isfinite(v) else f"{100 * v:.1f} %"


def _ms(v) -> str:
    return "" if not isinstance(v, (int, float)) or not math.isfinite(v) else f"{v:.0f}"


def blender_markdown(rows: list[LedgerRow], meta: dict) -> list[str]:
    """ledger.md's section on the Blender peers: per scene Skinlab's default frame beside EEVEE and
    Cycles against the truth, the frame times and the interleaved ratio."""
    b = meta.get("blender")
    if not b:
        return []
    L = ["## Peers: Blender (EEVEE, Cycles)", ""]
    if b.get("error"):
        return [*L, f"Not measured: {b['error']}", ""]
    L += [
        f"Blender {b.get('version')} (bpy, in a child process; skinlab/bench/blender_peer.py): the same scene, "
        "camera, lights and media (skinlab/bench/blender_scene.py), rendered in this run. Errors against the "
        "path-traced truth on 4x4 blocks (as the table above); frame times the median wall time of "
        "`bpy.ops.render.render` at the ledger's size after a warm-up (`first` is the scene's first render on "
        "that engine: EEVEE compiles its shaders there). `ratio` is Skinlab's default frame over EEVEE at 1 spp, "
        "both timed in interleaved rounds (HDR read back on Skinlab's side): below 1, Skinlab is faster.",
        "",
    ]
    default = default_setting().label
    scenes = list(dict.fromkeys(r.scene for r in rows))
    L.append(
        "| scene | setting | truth 4x4 | truth px | truth energy | own noise 4x4 | truth noise 4x4 | ms | first ms |"
    )
    L.append("|---|---|---|---|---|---|---|---|---|")
    for s in scenes:
        for r in [r for r in rows if r.scene == s and (r.peer or r.setting == default)]:
            status = "" if r.status == "ok" else f" ({r.status}: {r.error})"
            cells = [_pct(r.get(k)) for k in ("truth_rel_l1_block", "truth_rel_l1", "truth_energy")]
            cells += [_pct(r.get(k)) for k in ("peer_noise_block", "truth_noise_block")]
            cells += [_ms(r.get(k)) for k in ("frame_ms_median", "first_frame_ms")]
            L.append(f"| {s} | {r.setting}{status} | " + " | ".join(cells) + " |")
    ratios = b.get("ratios") or {}
    if ratios:
        L += [
            "",
            "| scene | Skinlab setting | Skinlab ms | EEVEE 1 spp ms | ratio (median of rounds) | rounds |",
            "|---|---|---|---|---|---|",
        ]
        for s, q in ratios.items():
            if "error" in q:
                L.append(f"| {s} | failed: {q['error']} | | | | |")
                continue
            rr = ", ".join(f"{x:.3f}" for x in q["per_round"])
            L.append(
                f"| {s} | {q['skinlab_setting']} | {q['skinlab_ms']:.1f} | {q['eevee_ms']:.1f} | {q['ratio']:.3f} "
                f"| {rr} |"
            )
    L.append("")
    return L
