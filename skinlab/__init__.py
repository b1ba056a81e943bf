"""Skinlab: a realtime subsurface-scattering workbench.

    import skinlab

    scene = skinlab.load("head")            # a bundled scene (`skinlab scenes`), a .toml or a mesh file
    frame = skinlab.render(scene, 320, 240, technique="tsd")
    frame.ldr                               # (240, 320, 4) uint8 sRGB

Layers, each a subpackage: ``skinlab.scene`` (scene graph, materials, loaders and the NumPy optics;
no GL), ``skinlab.gl`` (context, shader sources), ``skinlab.render`` (passes, techniques, the frame
plan), ``skinlab.truth`` (the path-traced reference), ``skinlab.bench`` (ledger and benchmarks),
``skinlab.viewer`` and ``skinlab.commands`` (the programs). ``skinlab.api`` is the Python API;
the names below are imported from it on first use, so ``import skinlab`` itself is cheap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__all__ = ["Skinlab", "__version__", "load", "render"]

if TYPE_CHECKING:  # pragma: no cover
    from skinlab.api import Skinlab, load, render


def __getattr__(name: str) -> Any:
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("skinlab")
        except PackageNotFoundError:  # pragma: no cover - a source tree that was never installed
            return "0+unknown"
    if name in ("Skinlab", "load", "render"):
        from skinlab import api

        return getattr(api, name)
    raise AttributeError(f"module 'skinlab' has no attribute {name!r}")
