"""Orbit / pan / zoom camera control (pure NumPy; no window needed, unit-tested).

The state is a turntable ("orbit") camera around a target point with world +Y up:

    eye = target + distance * (cos(pitch) sin(yaw), sin(pitch), cos(pitch) cos(yaw))

i.e. spherical coordinates of the offset eye - target, with yaw about +Y measured from +Z and
pitch the elevation above the XZ plane. Pitch is kept inside (-90 deg, 90 deg) so that the
view direction never becomes parallel to the up vector (where a look-at frame is undefined).

Pan moves the target in the camera's image plane by exactly the cursor's motion at the target's
depth: with a perspective camera of vertical field of view ``yfov`` the view frustum at distance
``d`` is ``2 d tan(yfov / 2)`` units high, so one pixel of an ``H``-pixel-high viewport spans
``2 d tan(yfov / 2) / H`` world units there (the pinhole projection, e.g. Hartley & Zisserman,
"Multiple View Geometry", 2nd ed., section 6.1). A point at the target's depth therefore follows
the cursor pixel for pixel. Zoom scales the distance geometrically (``factor ** steps``) so each
scroll step changes the apparent size by the same ratio.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

UP = np.array([0.0, 1.0, 0.0])
PITCH_LIMIT = math.radians(89.0)


def spherical_offset(yaw: float, pitch: float) -> np.ndarray:
    """Unit vector from the target towards the eye for the given yaw and pitch (radians)."""
    cp = math.cos(pitch)
    return np.array([cp * math.sin(yaw), math.sin(pitch), cp * math.cos(yaw)])


@dataclass
class OrbitCamera:
    target: np.ndarray
    distance: float
    yaw: float = 0.0
    pitch: float = 0.0
    orbit_speed: float = math.radians(0.4)  # radians per pixel of mouse motion
    zoom_factor: float = 0.9  # distance multiplier per scroll step (towards the target)
    min_distance: float = 1e-3
    max_distance: float = 1e6

    def __post_init__(self) -> None:
        self.target = np.asarray(self.target, np.float64).reshape(3).copy()
        if not np.isfinite(self.target).all():
            raise ValueError(f"orbit camera: target must be finite, got {self.target.tolist()}")
        if not (math.isfinite(self.distance) and self.distance > 0):
            raise ValueError(f"orbit camera: distance must be > 0, got {self.distance}")
        self.distance = float(min(max(self.distance, self.min_distance), self.max_distance))
        self.pitch = float(np.clip(self.pitch, -PITCH_LIMIT, PITCH_LIMIT))
        self._home = (self.target.copy(), self.distance, self.yaw, self.pitch)

    # -- construction ---------------------------------------------------------------------
    @classmethod
    def from_look_at(cls, eye, target, **kw) -> OrbitCamera:
        eye = np.asarray(eye, np.float64)
        target = np.asarray(target, np.float64)
        off = eye - target
        dist = float(np.linalg.norm(off))
        if dist == 0:
            raise ValueError("orbit camera: eye and target are the same point")
        pitch = math.asin(float(np.clip(off[1] / dist, -1.0, 1.0)))
        yaw = math.atan2(off[0], off[2])
        return cls(target, dist, yaw, pitch, **kw)

    @classmethod
    def from_camera_node(cls, camera, bounds: tuple[np.ndarray, np.ndarray] | None = None, **kw) -> OrbitCamera:
        """Orbit around the point on the camera's view axis nearest to the scene's centre (the
        scene file's look-at target is not kept by the camera node, only its orientation)."""
        m = camera.world_matrix
        eye = m[:3, 3].copy()
        fwd = -m[:3, 2] / np.linalg.norm(m[:3, 2])
        depth = 1.0
        if bounds is not None:
            lo, hi = (np.asarray(b, np.float64) for b in bounds)
            if np.isfinite(lo).all() and np.isfinite(hi).all() and (hi > lo).any():
                depth = float(np.dot((lo + hi) / 2 - eye, fwd))
                if depth <= 0:  # scene behind the camera: orbit about a point in front of it
                    depth = max(float(np.linalg.norm(hi - lo)), 1.0)
        return cls.from_look_at(eye, eye + fwd * depth, **kw)

    # -- state ------------------------------------------------------------------------------
    @property
    def eye(self) -> np.ndarray:
        return self.target + self.distance * spherical_offset(self.yaw, self.pitch)

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(right, up, forward) unit vectors of the view (forward points at the target)."""
        fwd = -spherical_offset(self.yaw, self.pitch)
        right = np.cross(fwd, UP)
        right /= np.linalg.norm(right)
        up = np.cross(right, fwd)
        return right, up, fwd

    def reset(self) -> None:
        t, d, y, p = self._home
        self.target, self.distance, self.yaw, self.pitch = t.copy(), d, y, p

    # -- interaction ----------------------------------------------------------------------
    def orbit(self, dx_px: float, dy_px: float) -> None:
        """Drag by (dx, dy) pixels (y up, as pyglet reports): dragging right turns the scene right."""
        self.yaw = (self.yaw - dx_px * self.orbit_speed) % (2 * math.pi)
        self.pitch = float(np.clip(self.pitch - dy_px * self.orbit_speed, -PITCH_LIMIT, PITCH_LIMIT))

    def world_per_pixel(self, viewport_height: int, yfov: float) -> float:
        return 2.0 * self.distance * math.tan(yfov / 2.0) / max(int(viewport_height), 1)

    def pan(self, dx_px: float, dy_px: float, viewport_height: int, yfov: float) -> None:
        """Move the target so that a point at its depth follows the cursor (y up)."""
        right, up, _ = self.basis()
        s = self.world_per_pixel(viewport_height, yfov)
        self.target = self.target - right * (dx_px * s) - up * (dy_px * s)

    def zoom(self, steps: float) -> None:
        """Positive steps (scroll up) move towards the target."""
        d = self.distance * self.zoom_factor ** float(steps)
        self.distance = float(min(max(d, self.min_distance), self.max_distance))

    def apply(self, camera) -> None:
        """Write the pose into a scene CameraNode."""
        camera.look_at(self.eye, self.target, UP)
