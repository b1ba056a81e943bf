"""GL state set in scopes: the capabilities (depth test, blending, face culling), the depth and blend
functions and the polygon offset a block of drawing needs, put back as they were when it ends (an
exception included), so that no pass or helper leaves them changed for the next.

Outside every scope the state is the baseline, moderngl's defaults: nothing enabled, depth test
``<``, blending ``SRC_ALPHA, ONE_MINUS_SRC_ALPHA``, no polygon offset. The renderer runs each pass in
a baseline scope (skinlab/render/renderer.py); a pass needing more opens its own::

    with gl_state(ctx, moderngl.DEPTH_TEST):
        ...
        with gl_state(ctx, enable=moderngl.BLEND, blend_func=(moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)):
            ...  # the enclosing scope's depth test and function, with blending on top

moderngl cannot read the state back, so the scopes keep it: one stack per context.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import moderngl


@dataclass(frozen=True)
class GlState:
    flags: int = moderngl.NOTHING  # the capabilities enabled (ctx.enable_only)
    depth_func: str = "<"
    blend_func: tuple[int, int] = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA)
    polygon_offset: tuple[float, float] = (0.0, 0.0)


BASELINE = GlState()
_STACKS: dict[int, list[GlState]] = {}  # id(ctx) -> the open scopes' states, innermost last


def current_state(ctx: moderngl.Context) -> GlState:
    """The state the innermost open scope set (BASELINE outside every scope)."""
    stack = _STACKS.get(id(ctx))
    return stack[-1] if stack else BASELINE


def _apply(ctx: moderngl.Context, s: GlState) -> None:
    ctx.enable_only(s.flags)
    ctx.depth_func = s.depth_func
    ctx.blend_func = s.blend_func
    ctx.polygon_offset = s.polygon_offset


@contextmanager
def gl_state(
    ctx: moderngl.Context,
    flags: int | None = None,
    *,
    enable: int = 0,
    depth_func: str | None = None,
    blend_func: tuple[int, int] | None = None,
    polygon_offset: tuple[float, float] | None = None,
) -> Iterator[GlState]:
    """Within the block: exactly `flags` enabled (None: the enclosing scope's) plus `enable`; each
    function given set, the others the enclosing scope's. On leaving, the enclosing scope's state
    again (the baseline outside every scope)."""
    outer = current_state(ctx)
    s = GlState(
        (outer.flags if flags is None else flags) | enable,
        outer.depth_func if depth_func is None else depth_func,
        outer.blend_func if blend_func is None else blend_func,
        outer.polygon_offset if polygon_offset is None else polygon_offset,
    )
    stack = _STACKS.setdefault(id(ctx), [])
    stack.append(s)
    _apply(ctx, s)
    try:
        yield s
    finally:
        stack.pop()
        if not stack:
            del _STACKS[id(ctx)]
        _apply(ctx, current_state(ctx))
