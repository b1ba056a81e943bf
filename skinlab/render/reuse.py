"""Reuse across frames: a pass whose inputs are unchanged since it last ran is not run again.

Each planned pass says what its output depends on (``PlannedPass.inputs``, built with the helpers
below from the scene's geometry versions and transforms, lights, materials, settings and scale) and
which of the plan's passes it reads (``PlannedPass.after``). Its *key* is its kind, its inputs, the
program cache's generation (a recompiled shader changes every result) and the keys of the passes it
reads, so a change upstream re-runs everything downstream. A pass with ``inputs = None`` depends on
the camera (forward shading, screen-space passes, tone mapping) and runs every frame.

The renderer keeps, per output resource (a GPU texture a pass object names through
``outputs(frame, planned)``), the key of the result it holds and the frame that computed it. A pass
is reused when every one of its outputs holds its current key: then the pass object's
``publish(frame, planned)`` hands the kept results to the frame (targets, matrices, per-frame data)
exactly as ``run`` would have, without drawing. Keying the outputs (not the pass names) keeps two
passes that share a texture (a shadow slot used by another light, level 0 written by the exact
convolution or the first blur) from ever reading each other's results.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from skinlab.scene.graph import LightNode, MeshNode, Scene
    from skinlab.scene.materials import Material

    from .frame_plan import PlannedPass

MAX_ENTRIES = 512  # kept output records; past this the record is cleared (a one-frame loss of reuse)


def matrix_key(m: np.ndarray) -> bytes:
    return np.asarray(m, np.float64).tobytes()


def node_geometry(node: MeshNode) -> tuple:
    """A mesh node's geometry: the mesh (identity and version) and its world transform."""
    return (node.uid, node.mesh.uid, node.mesh.version, matrix_key(node.world_matrix))


def scene_geometry(scene: Scene) -> tuple:
    """Every visible mesh's geometry (what a shadow map sees; its fit to the scene's bounds)."""
    return tuple(node_geometry(n) for n in scene.mesh_nodes())


def light_placement(light: LightNode) -> tuple:
    """Where a light is and its shape: its kind, position or direction, a spot's cone, an area light's
    size and orientation (what a shadow map and its softness depend on)."""
    if light.kind == "directional":
        return ("directional", light.direction.tobytes(), float(light.angular_radius))
    if light.kind == "point":
        return (light.kind, light.world_position.tobytes())
    shape = (light.inner_deg, light.outer_deg) if light.kind == "spot" else (light.width, light.height, light.radius)
    return (light.kind, light.world_position.tobytes(), light.world_matrix[:3, :3].tobytes(), shape)


def light_state(light: LightNode) -> tuple:
    """Where a light is and what it emits."""
    return (light.uid, *light_placement(light), np.asarray(light.radiance, np.float64).tobytes(), light.cast_shadow)


def material_state(material: Material) -> tuple:
    """Every declared value of a material (numbers, colours, map paths, the profile model)."""
    return tuple(sorted((k, v if not isinstance(v, list) else tuple(v)) for k, v in material.values.items()))


class ReuseRecord:
    """Which result each output resource holds: resource -> (key, frame number)."""

    def __init__(self) -> None:
        self.held: dict[Any, tuple[Any, int]] = {}

    def since(self, outputs, key) -> int | None:
        """The frame that computed the result all `outputs` hold if it is the one for `key`, else None."""
        frames = []
        for r in outputs:
            hit = self.held.get(r)
            if hit is None or hit[0] != key:
                return None
            frames.append(hit[1])
        return min(frames) if frames else None

    def record(self, outputs, key, frame_no: int) -> None:
        if len(self.held) > MAX_ENTRIES:
            self.held.clear()
        for r in outputs:
            self.held[r] = (key, frame_no)

    def forget(self, outputs) -> None:
        for r in outputs:
            self.held.pop(r, None)

    def clear(self) -> None:
        self.held.clear()


def pass_key(p: PlannedPass, keys: dict[str, Any], generation: int) -> Any:
    """The pass's full key (see the module docstring), or None when it runs every frame (no inputs,
    or it reads a pass that runs every frame or is not in the plan)."""
    if p.inputs is None:
        return None
    upstream = []
    for name in p.after:
        k = keys.get(name)
        if k is None:
            return None
        upstream.append(k)
    return (p.kind, p.resolution, p.inputs, generation, tuple(upstream))
