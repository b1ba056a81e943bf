"""Where the package's own files are: shaders, bundled assets and scenes, found through
``importlib.resources`` so that an installed wheel works from any directory, as a checkout does.

The bundled scenes are named by their path under ``skinlab/assets/scenes/`` without ``.toml``
(``head``, ``bunny-marble``, ``reference/slab-edge-skin1``); a reference scene may also be named
by its stem alone where that is unique (``slab-edge-skin1``). :func:`bundled_scenes` lists them
with the first line of each file's opening comment, which says what the scene is for.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

__all__ = ["BundledScene", "asset_path", "assets_root", "bundled_scenes", "scene_by_name", "shader_root"]


@cache
def _package_root() -> Path:
    # files() of a package installed as files (a wheel, an editable install, a checkout) is a real
    # directory; Skinlab's shaders hot-reload and its loaders read by path, so a zip import is not supported
    root = resources.files("skinlab")
    path = Path(str(root))
    if not path.is_dir():  # pragma: no cover - only a zipped install lands here
        raise RuntimeError(f"skinlab's package data must be on the file system, found {root}")
    return path


def shader_root() -> Path:
    """The folder of the GLSL sources (``skinlab/shaders``)."""
    return _package_root() / "shaders"


def assets_root() -> Path:
    """The folder of the bundled assets (``skinlab/assets``: meshes, textures, presets, scenes)."""
    return _package_root() / "assets"


def asset_path(*parts: str) -> Path:
    """A bundled asset's path, e.g. ``asset_path("presets", "jensen2001_table1.csv")``."""
    return assets_root().joinpath(*parts)


def scenes_root() -> Path:
    return assets_root() / "scenes"


@dataclass(frozen=True)
class BundledScene:
    name: str  # path under skinlab/assets/scenes without .toml, '/' separated
    path: Path
    summary: str  # the first line of the file's opening comment (each bundled scene makes it one line)


def _summary(path: Path) -> str:
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.strip()
        if not line:
            continue
        if not line.startswith("#"):
            break
        text = line.lstrip("#").strip()
        for prefix in ("Reference scene:", "The default scene:"):
            if text.startswith(prefix):
                text = text[len(prefix) :].strip()
        return text[:1].upper() + text[1:]
    return ""


def bundled_scenes() -> list[BundledScene]:
    """Every bundled scene, top-level scenes first, then the reference scenes, each sorted by name."""
    root = scenes_root()
    paths = sorted(root.rglob("*.toml"), key=lambda p: (len(p.relative_to(root).parts), p.as_posix()))
    return [BundledScene(p.relative_to(root).with_suffix("").as_posix(), p, _summary(p)) for p in paths]


def scene_by_name(name: str) -> Path | None:
    """The file of a bundled scene named ``name`` (see the module docstring), or None."""
    scenes = bundled_scenes()
    for s in scenes:
        if s.name == name:
            return s.path
    by_stem = [s for s in scenes if s.path.stem == name]
    return by_stem[0].path if len(by_stem) == 1 else None
