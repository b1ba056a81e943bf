"""Scene graph: nodes with local TRS and cached world matrices; mesh, light and camera nodes.

The scene holds data only; the renderer owns GL. A node's world matrix is cached and
recomputed only when its own transform or one above it changed (a dirty flag propagated down).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import transform as tf

if TYPE_CHECKING:
    from .measure import MeasureSpec


class Node:
    _uids = itertools.count(1)

    def __init__(
        self,
        name: str,
        translation=(0.0, 0.0, 0.0),
        rotation=(0.0, 0.0, 0.0, 1.0),
        scale=(1.0, 1.0, 1.0),
        visible: bool = True,
    ):
        self.uid = next(Node._uids)  # unique for the process (id() is reused after a node is freed)
        self.name = name
        self.parent: Node | None = None
        self.children: list[Node] = []
        self.visible = visible
        self._t = np.asarray(translation, np.float64).copy()
        self._r = np.asarray(rotation, np.float64).copy()
        self._s = np.asarray(scale, np.float64).copy()
        self._world: np.ndarray | None = None
        self.world_updates = 0  # how often the world matrix was recomputed (for tests/profiling)
        # a scene file's [[meshes]] entry: {"file", "flip_v", "generate_uvs"} on its top node (scene_save.py)
        self.file_info: dict | None = None

    # -- hierarchy ------------------------------------------------------------------
    def add(self, child: Node) -> Node:
        if child.parent is not None:
            child.parent.children.remove(child)
        child.parent = self
        self.children.append(child)
        child._invalidate()
        return child

    def walk(self) -> Iterator[Node]:
        """This node and its descendants, parents first, children in order (iterative: a file may
        nest thousands of nodes)."""
        stack = [self]
        while stack:
            n = stack.pop()
            yield n
            stack.extend(reversed(n.children))

    def is_visible(self) -> bool:
        n: Node | None = self
        while n is not None:
            if not n.visible:
                return False
            n = n.parent
        return True

    # -- transforms -------------------------------------------------------------------
    def _invalidate(self) -> None:
        stack = [self]
        while stack:
            n = stack.pop()
            if n._world is None:
                continue  # already dirty: so are its descendants
            n._world = None
            stack.extend(n.children)

    @property
    def translation(self) -> np.ndarray:
        return self._t.copy()

    @translation.setter
    def translation(self, v) -> None:
        self._t = np.asarray(v, np.float64).copy()
        self._invalidate()

    @property
    def rotation(self) -> np.ndarray:
        return self._r.copy()

    @rotation.setter
    def rotation(self, q) -> None:
        q = np.asarray(q, np.float64)
        if q.shape != (4,) or not np.isfinite(q).all() or np.linalg.norm(q) == 0:
            raise ValueError(f"node {self.name!r}: rotation must be a non-zero quaternion (x, y, z, w), got {q}")
        self._r = q / np.linalg.norm(q)
        self._invalidate()

    @property
    def scale(self) -> np.ndarray:
        return self._s.copy()

    @scale.setter
    def scale(self, s) -> None:
        self._s = np.asarray(s, np.float64).copy()
        self._invalidate()

    def set_matrix(self, m) -> None:
        t, r, s = tf.decompose(m)
        self._t, self._r, self._s = t, r, s
        self._invalidate()

    @property
    def local_matrix(self) -> np.ndarray:
        return tf.compose(self._t, self._r, self._s)

    @property
    def world_matrix(self) -> np.ndarray:
        if self._world is None:
            chain = [self]  # the ancestors whose world matrix is stale, nearest first (no recursion)
            while chain[-1].parent is not None and chain[-1].parent._world is None:
                chain.append(chain[-1].parent)
            for n in reversed(chain):
                local = n.local_matrix
                n._world = local if n.parent is None else n.parent._world @ local
                n.world_updates += 1
        assert self._world is not None  # made above
        return self._world

    @property
    def world_position(self) -> np.ndarray:
        return self.world_matrix[:3, 3].copy()

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.name!r})"


class MeshNode(Node):
    def __init__(self, name: str, mesh, material, **kw):
        super().__init__(name, **kw)
        self.mesh = mesh
        self.material = material


class LightNode(Node):
    """A light. ``directional``: travels along the node's -Z axis (``direction``); ``point``: at the
    node's position, intensity falling off with the inverse square of the distance in metres;
    ``spot``: a point light shining along -Z, full within ``inner_deg`` of its axis, fading linearly
    in angle to nothing at ``outer_deg`` (half-angles; Mitsuba's spot); ``rect``: a one-sided
    rectangle ``width`` x ``height`` (scene units) in the node's XY plane, emitting toward -Z;
    ``sphere``: a sphere of ``radius`` (scene units). color x intensity is the irradiance
    (directional), the intensity (point, spot) or the emitted radiance (rect, sphere)."""

    KINDS = ("directional", "point", "spot", "rect", "sphere")
    AREA_KINDS = ("rect", "sphere")

    def __init__(
        self,
        name: str,
        kind: str = "directional",
        color=(1.0, 1.0, 1.0),
        intensity: float = 1.0,
        cast_shadow: bool = False,
        **kw,
    ):
        shape = {k: kw.pop(k) for k in ("inner_deg", "outer_deg", "width", "height", "radius") if k in kw}
        super().__init__(name, **kw)
        if kind not in self.KINDS:
            raise ValueError(f"light {name!r}: type must be one of {self.KINDS}, got {kind!r}")
        if not np.isfinite(intensity) or intensity < 0:
            raise ValueError(f"light {name!r}: intensity must be finite and >= 0, got {intensity}")
        self.kind = kind
        self.color = np.asarray(color, np.float64)
        self.intensity = float(intensity)
        self.cast_shadow = bool(cast_shadow)
        # a directional light's angular radius (radians; > 0: soft shadows, e.g. a source of an
        # environment map, skinlab/scene/envmap.py)
        self.angular_radius = 0.0
        self.inner_deg, self.outer_deg = 30.0, 45.0  # spot
        self.width = self.height = 1.0  # rect
        self.radius = 0.5  # sphere
        for k, v in shape.items():
            setattr(self, k, v)
        self.check_shape()

    def check_shape(self) -> None:
        """ValueError naming the light when its cone or size is out of range."""
        if self.kind == "spot":
            i, o = self.inner_deg, self.outer_deg
            if not (np.isfinite(i) and np.isfinite(o) and 0.0 <= i <= o and 0.0 < o <= 90.0):
                raise ValueError(
                    f"light {self.name!r}: a spot needs 0 <= inner_deg <= outer_deg, 0 < outer_deg <= 90, got {i}, {o}"
                )
        for k in {"rect": ("width", "height"), "sphere": ("radius",)}.get(self.kind, ()):
            v = getattr(self, k)
            if not (np.isfinite(v) and v > 0):
                raise ValueError(f"light {self.name!r}: {k} must be a finite number > 0 (scene units), got {v}")

    @property
    def direction(self) -> np.ndarray:
        """Direction the light travels (world), i.e. the node's -Z axis."""
        d = -self.world_matrix[:3, 2]
        return d / np.linalg.norm(d)

    @property
    def radiance(self) -> np.ndarray:
        return self.color * self.intensity

    @property
    def is_area(self) -> bool:
        return self.kind in self.AREA_KINDS

    def half_extents(self) -> tuple[np.ndarray, np.ndarray]:
        """A rect's half-width and half-height vectors in the world (its node's X and Y axes)."""
        m = self.world_matrix[:3, :3]
        x, y = m[:, 0] / np.linalg.norm(m[:, 0]), m[:, 1] / np.linalg.norm(m[:, 1])
        return x * (self.width / 2), y * (self.height / 2)

    @property
    def size(self) -> float:
        """The light's extent that softens its shadows: a directional light's angular radius (radians),
        an area light's radius (a sphere's, a rect's half-diagonal; scene units), else 0."""
        if self.kind == "directional":
            return float(self.angular_radius)
        if self.kind == "sphere":
            return float(self.radius)
        if self.kind == "rect":
            return float(np.hypot(self.width, self.height) / 2)
        return 0.0


class CameraNode(Node):
    def __init__(
        self, name: str = "camera", yfov: float = np.radians(30), znear: float = 0.1, zfar: float = 1000.0, **kw
    ):
        super().__init__(name, **kw)
        if not (0 < yfov < np.pi):
            raise ValueError(f"camera {name!r}: yfov must be in (0, pi) radians, got {yfov}")
        if not (0 < znear < zfar):
            raise ValueError(f"camera {name!r}: need 0 < znear < zfar, got {znear}, {zfar}")
        self.yfov, self.znear, self.zfar = float(yfov), float(znear), float(zfar)

    def view_matrix(self) -> np.ndarray:
        return np.linalg.inv(self.world_matrix)

    def projection_matrix(self, aspect: float) -> np.ndarray:
        return tf.perspective(self.yfov, aspect, self.znear, self.zfar)

    def look_at(self, eye, target, up=(0.0, 1.0, 0.0)) -> None:
        self._t = np.asarray(eye, np.float64).copy()
        self._r = tf.look_at_rotation(eye, target, up)
        self._invalidate()


@dataclass
class Environment:
    """Light from all around the scene: a uniform ambient radiance and an optional HDR environment
    map (skinlab/scene/envmap.py: equirectangular, Mitsuba's axes), turned about +Y by rotation_deg
    and scaled by intensity; show_background draws the map behind the scene."""

    ambient: np.ndarray = field(default_factory=lambda: np.array([0.03, 0.03, 0.035]))
    exposure: float = 1.0
    map: Path | None = None  # an .exr or .hdr file
    rotation_deg: float = 0.0
    intensity: float = 1.0
    show_background: bool = False


class Scene:
    """The data of one scene: a node tree, a camera, and the physical scale."""

    def __init__(self, name: str = "scene", mm_per_unit: float = 1.0):
        if not (np.isfinite(mm_per_unit) and mm_per_unit > 0):
            raise ValueError(f"scene {name!r}: mm_per_unit must be > 0, got {mm_per_unit}")
        self.name = name
        self.mm_per_unit = float(mm_per_unit)
        self.root = Node("root")
        self.camera: CameraNode | None = None
        self.environment = Environment()
        self.source: Path | None = None  # path of the scene file, if any
        self.measure: MeasureSpec | None = None  # what the scene tests (a file's [measure])
        self.warnings: list[str] = []  # what loading met and could not honour (listed by every frame plan)

    def active_camera(self) -> CameraNode:
        """The camera, or ValueError naming the scene."""
        if self.camera is None:
            raise ValueError(f"scene {self.name!r} has no camera")
        return self.camera

    def add(self, node: Node, parent: Node | None = None) -> Node:
        (parent or self.root).add(node)
        if isinstance(node, CameraNode) and self.camera is None:
            self.camera = node
        return node

    def nodes(self) -> Iterator[Node]:
        return self.root.walk()

    def find(self, name: str) -> Node:
        for n in self.nodes():
            if n.name == name:
                return n
        raise KeyError(f"scene {self.name!r} has no node named {name!r}")

    def mesh_nodes(self, visible_only: bool = True) -> list[MeshNode]:
        return [n for n in self.nodes() if isinstance(n, MeshNode) and (not visible_only or n.is_visible())]

    def lights(self) -> list[LightNode]:
        return [n for n in self.nodes() if isinstance(n, LightNode) and n.is_visible()]

    def orbit_camera(self, degrees: float) -> None:
        """Swing the camera ``degrees`` about the world +Y axis through the centre of the visible
        meshes' bounds (positive: counter-clockwise seen from above, i.e. the camera moves to its
        right), keeping its distance, height and what it looks at relative to that centre."""
        if self.camera is None:
            raise ValueError(f"scene {self.name!r}: no camera to orbit")
        if not np.isfinite(degrees):
            raise ValueError(f"camera orbit: expected a finite angle in degrees, got {degrees}")
        lo, hi = self.world_bounds()
        c = (lo + hi) / 2
        a = np.radians(degrees)
        rot = np.eye(4)
        rot[0, 0], rot[0, 2], rot[2, 0], rot[2, 2] = np.cos(a), np.sin(a), -np.sin(a), np.cos(a)
        to, back = np.eye(4), np.eye(4)
        to[:3, 3], back[:3, 3] = -c, c
        world = back @ rot @ to @ self.camera.world_matrix
        parent = self.camera.parent.world_matrix if self.camera.parent is not None else np.eye(4)
        self.camera.set_matrix(np.linalg.inv(parent) @ world)

    def world_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for n in self.mesh_nodes():
            p = n.mesh.bound_corners() @ n.world_matrix[:3, :3].T + n.world_matrix[:3, 3]
            lo, hi = np.minimum(lo, p.min(0)), np.maximum(hi, p.max(0))
        if not np.isfinite(lo).all():
            return np.zeros(3), np.zeros(3)
        return lo, hi
