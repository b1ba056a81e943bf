"""Compute shaders for the screen- and texture-space passes (``RenderSettings.compute``).

A pass with a compute variant (tone mapping and the supersample filter, texture-space diffusion's
blurs and dilation, screen-space SSS, the disk gather, the exact convolution) runs it as a GL 4.3
compute shader or as its fragment shader, per pass, as the planner decides here:

- ``off``: the fragment shader;
- ``on``: the compute shader wherever the context runs compute shaders;
- ``auto`` (default): the path measured faster on this kind of device. On a GPU the compute path
  (every SM runs compute work, while vertex and pixel work runs on a few; docs/architecture.md
  "Compute passes"); on software GL (llvmpipe) what each pass declares (``software``: the path its
  measurement found faster there, docs/architecture.md has the figures).

Either way both paths read the same kernel data (tables, uniforms) and share their per-pixel GLSL
(an include both the ``.frag`` and the ``.comp`` call), so a change to a kernel reaches both; their
images agree to fp32 rounding (tests/render/test_compute.py). A context without compute shaders (the
viewer's window asks for GL 3.3 core) runs the fragment path, and the plan says why.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import moderngl

if TYPE_CHECKING:
    from skinlab.gl.programs import ProgramCache
    from skinlab.gl.uniforms import Shader


class ComputeSetting(Protocol):
    """What :func:`choose_path` reads of the settings (``RenderSettings.compute``; the settings
    import this module for COMPUTE_CHOICES, so it names no settings class)."""

    compute: str


COMPUTE_CHOICES = ("auto", "on", "off")
LOCAL_SIZE = 8  # work groups of 8 x 8 invocations (local_size_x/y in every .comp)


@dataclass(frozen=True)
class Device:
    """What the planner knows of the GL context a frame runs on (no GL calls while planning)."""

    compute: str | None = "the planner was given no GL context"  # None: runs compute shaders; else why not
    software: bool = False  # software rasteriser (llvmpipe)

    @classmethod
    def of(cls, ctx: moderngl.Context) -> Device:
        from skinlab.gl.context import compute_unavailable, software_gl

        return cls(compute_unavailable(ctx), software_gl(ctx))


NO_DEVICE = Device()


@dataclass(frozen=True)
class PassPath:
    """How one planned pass runs: compute or fragment shader, and why (for the plan's reason)."""

    compute: bool
    why: str

    @property
    def note(self) -> str:
        return f"; {'compute' if self.compute else 'fragment'} shader ({self.why})"


def choose_path(settings: ComputeSetting, device: Device | None, software: str = "compute") -> PassPath:
    """The path of a pass with a compute variant. `software`: the path ``auto`` takes on software GL
    ("compute" or "fragment", from the pass's measurement there)."""
    device = device or NO_DEVICE
    mode = settings.compute
    if mode == "off":
        return PassPath(False, "compute off")
    if device.compute is not None:
        return PassPath(False, f"compute {mode}, but {device.compute}")
    if mode == "on":
        return PassPath(True, "compute on")
    if device.software and software != "compute":
        return PassPath(False, "auto: faster than its compute shader on software GL")
    return PassPath(True, "auto: faster than its fragment shader on software GL" if device.software else "auto: GPU")


def dispatch(cs: moderngl.ComputeShader, size: tuple[int, int], barrier: bool = True) -> None:
    """Run `cs` over a `size` (width, height) grid in LOCAL_SIZE x LOCAL_SIZE work groups (every .comp
    returns for invocations outside the size), then make its image stores visible to what reads them
    next (texture fetches, image loads, framebuffer reads, read-backs)."""
    w, h = size
    cs.run((w + LOCAL_SIZE - 1) // LOCAL_SIZE, (h + LOCAL_SIZE - 1) // LOCAL_SIZE, 1)
    if barrier:
        cs.ctx.memory_barrier()


def bind_images(cs: moderngl.ComputeShader, images: dict) -> None:
    """Bind each texture to the image uniform named by its key, on image units 0, 1, ... in order,
    for writing (the .comp files declare them ``writeonly``; what they read is a sampler)."""
    from skinlab.gl.uniforms import set_uniform

    for unit, (name, tex) in enumerate(images.items()):
        tex.bind_to_image(unit, read=False, write=True)
        set_uniform(cs, name, unit)


def pass_program(programs: ProgramCache, shader: str, compute: bool, defines: dict | None = None) -> Shader:
    """The two paths of a pass that has both: `shader` (a path under the shader root, no ending) as
    the compute shader ``<shader>.comp`` or as the fullscreen fragment pass ``<shader>.frag``."""
    if compute:
        return programs.compute(f"{shader}.comp", defines or {})
    return programs.get("passes/fullscreen.vert", f"{shader}.frag", defines or {})
