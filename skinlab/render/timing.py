"""Per-pass timing: GPU timer queries and CPU wall time (synchronised with glFinish).

On Mesa llvmpipe the timer query sees only command submission, not the software rasteriser's
work, so the synchronised wall time is the meaningful figure there; on a real GPU the timer
query is. ``FrameTimings.frame_ms`` picks accordingly.
"""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import moderngl

from skinlab.gl.context import software_gl

_INVALID = 0xFFFFFFFF  # some drivers return UINT_MAX for a query without a result


@dataclass
class PassTime:
    name: str
    gpu_ms: float | None
    cpu_ms: float
    # the process's CPU time over the pass, every thread's (synchronised passes only, else None): on
    # software GL the rasteriser's own work, which a machine shared with other jobs inflates far
    # less than the wall time
    process_ms: float | None = None


@dataclass
class FrameTimings:
    passes: list[PassTime] = field(default_factory=list)
    software_gl: bool = False

    @property
    def frame_ms(self) -> float:
        gpu = [p.gpu_ms for p in self.passes if p.gpu_ms is not None]
        if not self.software_gl and self.passes and len(gpu) == len(self.passes):
            return sum(gpu)
        return sum(p.cpu_ms for p in self.passes)

    def table(self) -> str:
        """Per-pass times as an aligned table with the frame total (skinlab render and demo)."""
        clock = "CPU, synchronised; software GL" if self.software_gl else "GPU timer queries"
        width = max([len(p.name) for p in self.passes] + [len("frame (total)")])
        lines = [f"per-pass time in ms (frame time from: {clock})", f"  {'pass':<{width}}  {'cpu':>9}  {'gpu':>9}"]
        for p in self.passes:
            gpu = f"{p.gpu_ms:9.2f}" if p.gpu_ms is not None else f"{'n/a':>9}"
            lines.append(f"  {p.name:<{width}}  {p.cpu_ms:9.2f}  {gpu}")
        lines.append(f"  {'-' * width}  {'-' * 9}  {'-' * 9}")
        measured = [p.gpu_ms for p in self.passes if p.gpu_ms is not None]
        gpu_total = f"{sum(measured):9.2f}" if self.passes and len(measured) == len(self.passes) else f"{'n/a':>9}"
        lines.append(f"  {'frame (total)':<{width}}  {sum(p.cpu_ms for p in self.passes):9.2f}  {gpu_total}")
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {
            "frame_ms": self.frame_ms,
            "clock": "cpu-synchronised" if self.software_gl else "gpu-timer",
            "passes": {
                p.name: {"gpu_ms": p.gpu_ms, "cpu_ms": p.cpu_ms, "process_ms": p.process_ms} for p in self.passes
            },
        }


class PassTimer:
    def __init__(self, ctx: moderngl.Context, sync: bool = True):
        self.ctx = ctx
        self.sync = sync
        self.software_gl = software_gl(ctx)
        self.frame = FrameTimings(software_gl=self.software_gl)
        self._queries: list[moderngl.Query] = []

    def start_frame(self) -> None:
        self.frame = FrameTimings(software_gl=self.software_gl)

    @contextmanager
    def measure(self, name: str):
        q = self.ctx.query(time=True)
        if self.sync:
            self.ctx.finish()  # the work queued before is not this pass's
        c0, t0 = time.process_time(), time.perf_counter()
        with q:
            yield
        if self.sync:
            self.ctx.finish()
        cpu = (time.perf_counter() - t0) * 1e3
        process = (time.process_time() - c0) * 1e3 if self.sync else None
        try:
            ns = q.elapsed
            gpu = None if ns in (_INVALID, 0) and self.software_gl else (None if ns >= _INVALID else ns / 1e6)
        except Exception:
            gpu = None
        self.frame.passes.append(PassTime(name, gpu, cpu, process))
