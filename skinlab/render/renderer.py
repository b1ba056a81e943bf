"""The renderer owns GL: programs, GPU resources and the passes; it runs a frame plan."""

from __future__ import annotations

import time
from collections.abc import Generator, Iterator
from dataclasses import dataclass

import moderngl
import numpy as np

from skinlab.gl.programs import ProgramCache
from skinlab.gl.shader_source import ShaderLibrary
from skinlab.gl.state import gl_state
from skinlab.scene.graph import Scene

from .bounce import BouncePass
from .compute import Device
from .environment import EnvironmentPass, SkyOcclusionPass
from .frame import Frame
from .frame_plan import FramePlan
from .gpu_resources import GpuResources
from .passes.forward import ForwardPass
from .passes.shadow import FittedShadowPass, ShadowPass
from .passes.tonemap import TonemapPass
from .plan import plan_frame
from .registry import get_technique, pass_class
from .reuse import ReuseRecord, pass_key
from .settings import RenderSettings
from .supersample import nearest_depth
from .technique import RenderPass, TechniqueState
from .through_kernel import ThroughPass
from .timing import FrameTimings, PassTimer


@dataclass
class FrameResult:
    hdr: np.ndarray  # (H, W, 4) float32 linear radiance, alpha = coverage; row 0 = top (supersampled: box-filtered)
    ldr: np.ndarray  # (H, W, 4) uint8 sRGB, tone mapped
    depth: np.ndarray  # (H, W) float32 eye-space distance along -Z (scene units), inf = background
    timings: FrameTimings
    plan: FramePlan
    cpu_ms: float


class Renderer:
    def __init__(self, ctx: moderngl.Context, library: ShaderLibrary | None = None):
        self.ctx = ctx
        self.programs = ProgramCache(ctx, library)
        self.device = Device.of(ctx)  # what the planner may use (compute shaders; skinlab/render/compute.py)
        self.resources = GpuResources(ctx)
        self.timer = PassTimer(ctx)
        # the core's passes; a technique's are made on first use (pass_for)
        self.passes: dict[str, RenderPass] = {
            "shadow": ShadowPass(self),
            "shadow_fit": FittedShadowPass(self),
            "bounce": BouncePass(self),
            "through": ThroughPass(self),
            "environment": EnvironmentPass(self),
            "sky_occlusion": SkyOcclusionPass(self),
            "forward": ForwardPass(self),
            "tonemap": TonemapPass(self),
        }
        self.states: dict[str, TechniqueState] = {}  # techniques' GPU state kept across frames, by key
        self._fs_vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], dtype="f4").tobytes())
        self._fs_vaos: dict[int, moderngl.VertexArray] = {}
        self._dummy_shadow: moderngl.Texture | None = None
        self._dummy_texture: moderngl.Texture | None = None
        self.last_frame: Frame | None = None  # the latest frame's targets (viewer's pass inspector)
        # reuse across frames (skinlab/render/reuse.py): a pass whose inputs are unchanged since it last
        # ran is not run again; False runs every pass every frame (benchmarks of the full frame)
        self.reuse = True
        self.reuse_record = ReuseRecord()
        self.frame_number = 0  # frames rendered by this renderer (the plan's "since frame N")

    # -- helpers for passes -----------------------------------------------------------
    def fullscreen(self, prog: moderngl.Program) -> None:
        vao = self._fs_vaos.get(id(prog))
        if vao is None or vao.program is not prog:
            vao = self._fs_vaos[id(prog)] = self.ctx.vertex_array(prog, [(self._fs_vbo, "2f", "in_pos")])
        vao.render(moderngl.TRIANGLES)

    def state(self, key: str, factory):
        """A technique's state kept across frames (made by factory(ctx) on first use)."""
        st = self.states.get(key)
        if st is None:
            st = self.states[key] = factory(self.ctx)
        return st

    def pass_for(self, kind: str) -> RenderPass:
        p = self.passes.get(kind)
        if p is None:
            cls = pass_class(kind)
            if cls is None:
                raise ValueError(f"frame plan: no registered pass for kind {kind!r}")
            p = self.passes[kind] = cls(self)
        return p

    def dummy_texture(self) -> moderngl.Texture:
        """A 1x1 float texture for a sampler with nothing to read (value 1e30: 'no surface')."""
        if self._dummy_texture is None:
            self._dummy_texture = self.ctx.texture((1, 1), 4, np.full(4, 1e30, np.float32).tobytes(), dtype="f4")
        return self._dummy_texture

    def dummy_shadow_map(self) -> moderngl.Texture:
        if self._dummy_shadow is None:
            t = self.ctx.depth_texture((1, 1), data=np.ones(1, np.float32).tobytes())
            t.compare_func = "<="
            self._dummy_shadow = t
        return self._dummy_shadow

    # -- a frame ------------------------------------------------------------------------
    def plan(self, scene: Scene, settings: RenderSettings) -> FramePlan:
        t = get_technique(settings.technique_name)
        return plan_frame(scene, settings, self.state(*t.state) if t.state is not None else None, self.device)

    def render(
        self, scene: Scene, settings: RenderSettings | None = None, readback: bool | tuple[str, ...] = True
    ) -> FrameResult:
        """Plan and run a frame. ``readback``: True for all of hdr/ldr/depth, False for none, or a
        tuple naming the ones wanted (the others come back as None)."""
        steps = self.frame_steps(scene, settings, readback)
        while True:
            try:
                next(steps)
            except StopIteration as done:
                return done.value

    def frame_steps(
        self, scene: Scene, settings: RenderSettings | None = None, readback: bool | tuple[str, ...] = True
    ) -> Generator[str, None, FrameResult]:
        """:meth:`render` in steps: a generator that yields the name of each pass it has just run and
        returns the FrameResult (StopIteration.value). The viewer runs a few steps per turn of its
        event loop, so that a slow frame never keeps the window from answering; between steps the
        caller may draw with GL (each pass sets the state it needs). ``cpu_ms`` counts the steps' own
        time, not the caller's in between."""
        settings = settings or RenderSettings()
        t0 = time.perf_counter()
        cam = scene.camera
        if cam is None:
            raise ValueError(f"scene {scene.name!r} has no camera")
        plan = self.plan(scene, settings)
        for st in self.states.values():  # a technique's state keeps what this frame uses
            st.begin_frame(plan)
        self.resources.vertex_streams = plan.vertex_streams  # the meshes' extra inputs this frame
        frame = Frame(
            scene,
            settings,
            cam.view_matrix(),
            cam.projection_matrix(settings.width / settings.height),
            cam.world_position,
        )
        self.frame_number += 1
        self.timer.start_frame()
        busy, t0 = time.perf_counter() - t0, time.perf_counter()
        for name in self._pass_steps(frame, plan):
            busy += time.perf_counter() - t0
            yield name
            t0 = time.perf_counter()
        self.last_frame = frame
        wanted = ("hdr", "ldr", "depth") if readback is True else (readback or ())
        hdr, ldr, depth = self.read_targets(frame, wanted)
        return FrameResult(hdr, ldr, depth, self.timer.frame, plan, (busy + time.perf_counter() - t0) * 1e3)

    def run_passes(self, frame: Frame, plan: FramePlan) -> None:
        """Run the plan's passes in order; with ``self.reuse`` a pass whose outputs still hold the
        result for its current inputs is published from them instead (PlannedPass.reused_since)."""
        for _ in self._pass_steps(frame, plan):
            pass

    def _pass_steps(self, frame: Frame, plan: FramePlan) -> Iterator[str]:
        keys: dict[str, object] = {}
        record = self.reuse_record
        for p in plan.passes:
            impl = self.pass_for(p.kind)
            key = keys[p.name] = pass_key(p, keys, self.programs.generation)
            outputs = impl.outputs(frame, p) if key is not None else ()
            if self.reuse and outputs:
                since = record.since(outputs, key)
                if since is not None:
                    impl.publish(frame, p)
                    p.reused_since = since
                    continue
            record.forget(outputs)  # a run that fails half-way leaves them holding nothing known
            with self.timer.measure(p.name), gl_state(self.ctx):  # each pass from the baseline, and back
                impl.run(frame, p)
            if outputs:
                record.record(outputs, key, self.frame_number)
            yield p.name

    def forget_reuse(self) -> None:
        """Run every pass on the next frame (after a change the input keys cannot see)."""
        self.reuse_record.clear()

    def read_targets(self, frame: Frame, wanted=("hdr", "ldr", "depth")):
        """hdr, ldr and depth at the output size (None where not wanted). With supersampling the hdr
        is the box-filtered linear radiance (the tone-mapping pass's ``hdr_filtered``) and the depth
        each pixel's nearest sample (skinlab/render/supersample.py)."""
        w, h = frame.settings.size
        n = frame.settings.supersample
        hdr = ldr = depth = None
        if "hdr" in wanted:
            src = frame.targets["hdr_filtered" if n > 1 else "hdr_color"]
            hdr = np.frombuffer(src.read(), np.float32).reshape(h, w, 4)[::-1].copy()
        if "ldr" in wanted:
            ldr = np.frombuffer(frame.targets["ldr_color"].read(), np.uint8).reshape(h, w, 4)[::-1].copy()
        if "depth" not in wanted:
            return hdr, ldr, None
        zbuf = np.frombuffer(frame.targets["depth"].read(), np.float32).reshape(h * n, w * n)[::-1]
        zbuf = nearest_depth(zbuf, n)
        cam = frame.scene.active_camera()
        near, far = cam.znear, cam.zfar
        zn = zbuf.astype(np.float64) * 2.0 - 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            lin = 2.0 * near * far / (far + near - zn * (far - near))
        depth = np.where(zbuf >= 1.0, np.inf, lin).astype(np.float32)
        return hdr, ldr, depth

    def release(self) -> None:
        """Release every GPU object the renderer made; it stays usable (all are made again on demand)."""
        for p in self.passes.values():
            p.release()
        for vao in self._fs_vaos.values():
            vao.release()
        self._fs_vaos.clear()
        for t in (self._dummy_shadow, self._dummy_texture):
            if t is not None:
                t.release()
        self._dummy_shadow = self._dummy_texture = None
        self.programs.release()
        self.resources.release()
        self.reuse_record.clear()
        for st in self.states.values():
            st.release()
        self.states.clear()
