"""Light from all around, for every pass that shades it (skinlab/shaders/lib/ambient.glsl): the variant
defines and bindings of the interreflection's bounce light (skinlab/render/bounce.py) and the
environment map (skinlab/render/environment.py) in one place, so a pass that shades ambient light
takes both by calling these two."""

from __future__ import annotations

from .bounce import bind_bounce, bounce_defines
from .environment import bind_environment, environment_defines


def ambient_defines(frame, node) -> dict:
    """``BOUNCE``, ``ENV_MAP``, ``SKY_OCCLUSION`` as this frame has them for `node`."""
    return {**bounce_defines(frame, node), **environment_defines(frame, node)}


def bind_ambient(frame, node, prog, units) -> None:
    """Bounce light and the environment map for a program compiled with :func:`ambient_defines`."""
    bind_bounce(frame, node, prog, units)
    bind_environment(frame, node, prog, units)
