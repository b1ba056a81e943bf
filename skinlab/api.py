"""Skinlab from Python: load a scene (or a mesh file), render it headless, get NumPy arrays.

    from skinlab import Skinlab, load

    scene = load("head")                              # a bundled scene by name, a .toml, or load("model.obj")
    scene.find("head").visible = True                # the scene graph is plain Python (skinlab/scene/graph.py)
    with Skinlab() as lab:                            # one headless GL context (EGL), reused per render
        frame = lab.render(scene, 640, 480, technique="tsd", size=256, exposure=1.5, camera_orbit=30)
    frame.ldr    # (480, 640, 4) uint8, tone mapped sRGB, row 0 at the top (what a PNG holds)
    frame.hdr    # (480, 640, 4) float32 linear radiance, alpha = coverage
    frame.depth  # (480, 640) float32 distance along the view axis in scene units, inf = background
    print(frame.timings.table())

``render(...)`` takes the fields of :class:`skinlab.render.settings.RenderSettings` as keywords
(``technique``, ``sss_model``, ``shadow_size``, ``supersample``, ...) and the chosen technique's own settings
(``size=256`` for tsd's irradiance texels; `skinlab render --help` lists them per technique; an
unknown one is an error naming it), plus ``exposure`` (a linear
multiplier, as ``[environment] exposure``) and ``camera_orbit`` (degrees about the vertical axis
through the meshes' centre, as ``skinlab render --camera-orbit``); both apply to this render only.
Materials are edited with ``node.material.update({"roughness": 0.3})``, which validates each
value against its declaration (docs/scenes.md), and take a measured medium with
``node.material.apply_preset("marble")`` (or ``update({"preset": "marble"})``). Errors are
``ValueError`` naming the file or parameter. A library module: it never imports the command line.
"""

from __future__ import annotations

from pathlib import Path

from skinlab.render.registry import DEFAULT_TECHNIQUE
from skinlab.render.renderer import FrameResult, Renderer
from skinlab.render.settings import RenderSettings
from skinlab.scene.graph import Scene
from skinlab.scene.scenefile import load_scene

__all__ = ["Skinlab", "load", "render"]


def load(
    path: str | Path | None = None,
    *,
    preset: str | None = None,
    mm_per_unit: float | None = None,
    set: dict | None = None,
) -> Scene:
    """A bundled scene by name (``"head"``, ``"bunny-marble"``; ``skinlab scenes`` lists them), a scene
    file (TOML) or a mesh file (.glb .gltf .obj .ply .stl .off); None: the bundled head. ``preset``,
    ``mm_per_unit`` and ``set`` (``{"roughness": 0.3, "environment.exposure": 2}``) edit it before it is
    built, as ``skinlab render --preset --mm-per-unit --set KEY=VALUE`` do (skinlab/scene/scene_edits.py)."""
    from skinlab.scene.scene_edits import make_edits

    return load_scene(path, make_edits(preset, mm_per_unit, list((set or {}).items())))


class Skinlab:
    """A headless renderer: one EGL context and its GPU caches (programs, meshes, textures), so
    rendering the same scene again is fast. Use as a context manager or call :meth:`close`."""

    def __init__(self):
        from skinlab.gl.context import create_headless_context

        self.ctx = create_headless_context()
        self.renderer = Renderer(self.ctx)

    def render(
        self,
        scene: Scene | str | Path | None = None,
        width: int = 640,
        height: int = 640,
        *,
        exposure: float | None = None,
        camera_orbit: float = 0.0,
        warm_up: bool = True,
        **settings,
    ) -> FrameResult:
        """Render ``scene`` (a Scene, a path, or None for the head) and read back hdr, ldr and depth.
        ``warm_up`` renders once first, so that timings exclude shader compiles and uploads."""
        if not isinstance(scene, Scene):
            scene = load_scene(scene)
        technique = settings.pop("technique", None)
        if technique is None or isinstance(technique, str):  # a name and keywords for its settings
            st = RenderSettings.for_technique(technique or DEFAULT_TECHNIQUE, width, height, **settings)
        else:  # a technique's settings object
            st = RenderSettings(width, height, technique=technique, **settings)
        if exposure is not None and not (0 < exposure < float("inf")):
            raise ValueError(f"exposure: expected a finite multiplier > 0, got {exposure}")
        saved_exposure, saved_camera = scene.environment.exposure, None
        try:
            if exposure is not None:
                scene.environment.exposure = float(exposure)
            if camera_orbit:
                saved_camera = scene.active_camera().local_matrix.copy()
                scene.orbit_camera(camera_orbit)
            if warm_up:
                self.renderer.render(scene, st, readback=False)
            return self.renderer.render(scene, st)
        finally:
            scene.environment.exposure = saved_exposure
            if saved_camera is not None:
                scene.active_camera().set_matrix(saved_camera)

    def close(self) -> None:
        self.renderer.release()

    def __enter__(self) -> Skinlab:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def render(scene: Scene | str | Path | None = None, width: int = 640, height: int = 640, **kw) -> FrameResult:
    """One render with a fresh :class:`Skinlab` (for many renders keep one Skinlab instead)."""
    with Skinlab() as lab:
        return lab.render(scene, width, height, **kw)
