"""Texture units handed out per draw: a pass binds each sampler through one allocator instead of
numbering units by hand across files (material maps, shadow maps, a technique's textures)."""

from __future__ import annotations

import moderngl

from skinlab.gl.uniforms import set_uniform

MIN_UNITS = 16  # GL 3.3 guarantees 16 fragment texture image units
_LIMITS: dict[int, int] = {}  # id(context) -> its unit count (ctx.info queries the driver every time)


def unit_limit(ctx: moderngl.Context | None) -> int:
    if ctx is None:
        return MIN_UNITS
    n = _LIMITS.get(id(ctx))
    if n is None:
        n = _LIMITS[id(ctx)] = int(ctx.info.get("GL_MAX_TEXTURE_IMAGE_UNITS", MIN_UNITS))
    return n


class TextureUnits:
    """Units 0, 1, 2, ... in the order samplers are bound; one allocator per program use."""

    def __init__(self, ctx: moderngl.Context | None = None):
        self.limit = unit_limit(ctx)
        self.bound: dict[str, int] = {}  # sampler uniform -> unit

    def bind(self, prog: moderngl.Program, sampler: str, texture) -> int:
        """Put `texture` on the next free unit and point `sampler` at it (a sampler the program does
        not use still gets a unit: binding never depends on what the compiler kept)."""
        unit = self.bound.get(sampler)
        if unit is None:
            unit = len(self.bound)
            if unit >= self.limit:
                raise RuntimeError(
                    f"texture units: {sampler} needs unit {unit}, but the GL offers {self.limit} "
                    f"(bound: {', '.join(self.bound)})"
                )
            self.bound[sampler] = unit
        texture.use(unit)
        set_uniform(prog, sampler, unit)
        return unit
