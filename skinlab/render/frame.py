"""Per-frame state shared between passes: the scene, matrices, targets produced so far."""

from __future__ import annotations

from dataclasses import dataclass, field

import moderngl
import numpy as np

from skinlab.scene.graph import Scene

from .settings import RenderSettings


@dataclass
class Frame:
    scene: Scene
    settings: RenderSettings
    view: np.ndarray
    proj: np.ndarray
    camera_pos: np.ndarray
    targets: dict[str, moderngl.Texture] = field(default_factory=dict)
    shadow_matrices: dict[int, np.ndarray] = field(default_factory=dict)
    shadow_fine_matrices: dict[int, np.ndarray] = field(default_factory=dict)  # slot -> its fitted map's
    shadow_eyes: dict[int, np.ndarray] = field(default_factory=dict)  # slot -> light pos (w=1) / dir (w=0)
    data: dict[str, dict] = field(default_factory=dict)  # a technique's per-frame data, by its state key

    @property
    def view_proj(self) -> np.ndarray:
        return self.proj @ self.view
