"""Standalone (headless) moderngl contexts through EGL.

Works on Mesa llvmpipe without a GPU and on NVIDIA's EGL. Where several EGL devices exist,
``SKINLAB_EGL_DEVICE`` (an index) chooses one. A failure names the missing library and the
package that provides it instead of a traceback from the loader.
"""

from __future__ import annotations

import ctypes.util
import os
from typing import Any

import moderngl

GL_VERSION = 330
COMPUTE_GL_VERSION = 430  # compute shaders (the subsurface passes' compute path, skinlab/render/compute.py)

_HINTS = {
    "libEGL": "libEGL.so.1 (Debian/Ubuntu: apt-get install libegl1 libegl-mesa0)",
    "libGL": "libGL.so.1 (Debian/Ubuntu: apt-get install libgl1 libgl1-mesa-dri)",
    "gbm": "libgbm.so.1 (Debian/Ubuntu: apt-get install libgbm1)",
}


class ContextError(RuntimeError):
    """No OpenGL context could be created; the message says what to install."""


def _missing_libraries() -> list[str]:
    missing = []
    for name, hint in (("EGL", _HINTS["libEGL"]), ("GL", _HINTS["libGL"])):
        if ctypes.util.find_library(name) is None:
            missing.append(hint)
    return missing


def egl_device_index() -> int:
    raw = os.environ.get("SKINLAB_EGL_DEVICE", "0").strip() or "0"
    try:
        idx = int(raw)
    except ValueError:
        raise ContextError(f"SKINLAB_EGL_DEVICE must be a device index (0, 1, ...), got {raw!r}") from None
    if idx < 0:
        raise ContextError(f"SKINLAB_EGL_DEVICE must be >= 0, got {idx}")
    return idx


_SHARED: moderngl.Context | None = None


def create_headless_context(shared: bool = True) -> moderngl.Context:
    """A standalone OpenGL 3.3+ core context through EGL.

    By default one context per process is shared: moderngl does not make a standalone context
    current again before each call, so a second one would silently take over the GL state."""
    global _SHARED
    if shared and _SHARED is not None:
        return _SHARED
    missing = _missing_libraries()
    if missing:
        raise ContextError(
            "cannot create a headless OpenGL context; missing: "
            + "; ".join(missing)
            + ". `make setup` installs them where apt-get is available."
        )
    idx = egl_device_index()
    kwargs: dict[str, Any] = {"device_index": idx} if idx else {}
    try:
        # (moderngl's stub types each of **settings as a dict)
        create: Any = moderngl.create_context
        ctx = create(standalone=True, backend="egl", require=GL_VERSION, **kwargs)
    except Exception as exc:  # glcontext raises plain Exceptions with terse text
        text = str(exc).strip() or exc.__class__.__name__
        hint = ""
        low = text.lower()
        if "device" in low and idx:
            hint = f" (SKINLAB_EGL_DEVICE={idx}: no such EGL device; try 0)"
        elif "libegl" in low or "egl" in low:
            hint = "; EGL needs " + _HINTS["libEGL"] + " and Mesa's drivers " + _HINTS["libGL"]
        raise ContextError(f"cannot create a headless OpenGL context through EGL: {text}{hint}") from None
    if shared:
        _SHARED = ctx
    return ctx


def compute_unavailable(ctx: moderngl.Context) -> str | None:
    """None when `ctx` runs compute shaders (OpenGL 4.3 or newer), else why not, in words. The
    headless context asks for 3.3 as a minimum and gets the newest core profile the driver has
    (llvmpipe: 4.5); the viewer's window asks for 3.3 core and may get exactly that."""
    code = int(getattr(ctx, "version_code", 0) or 0)
    if code >= COMPUTE_GL_VERSION:
        return None
    return f"the GL context is {code // 100}.{code % 100 // 10} (compute shaders need 4.3)"


def software_gl(ctx: moderngl.Context) -> bool:
    """Whether `ctx` rasterises in software (Mesa llvmpipe or softpipe)."""
    name = ctx.info.get("GL_RENDERER", "").lower()
    return "llvmpipe" in name or "softpipe" in name


def describe(ctx: moderngl.Context) -> str:
    info = ctx.info
    return f"{info.get('GL_RENDERER', '?')} / {info.get('GL_VERSION', '?')}"
