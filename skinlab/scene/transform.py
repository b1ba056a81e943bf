"""Small 4x4 transform helpers (column vectors, OpenGL conventions: camera looks down -Z)."""

from __future__ import annotations

import numpy as np


def quat_to_matrix(q) -> np.ndarray:
    """3x3 rotation from a unit quaternion (x, y, z, w), glTF order."""
    x, y, z, w = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_to_quat(m) -> np.ndarray:
    """Unit quaternion (x, y, z, w) from a 3x3 rotation (Shepperd's method)."""
    m = np.asarray(m, dtype=np.float64)[:3, :3]
    t = np.trace(m)
    if t > 0:
        s = np.sqrt(t + 1.0) * 2
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(m)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k]) * 2
        q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j, i] + m[i, j]) / s
        q[k] = (m[k, i] + m[i, k]) / s
    quat = np.array(q)
    return quat / np.linalg.norm(quat)


def euler_deg_to_quat(angles) -> np.ndarray:
    """Quaternion for rotations about X, then Y, then Z (degrees), i.e. R = Rz Ry Rx."""
    ax, ay, az = np.radians(np.asarray(angles, dtype=np.float64))
    rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    return matrix_to_quat(rz @ ry @ rx)


def compose(translation, rotation, scale) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = quat_to_matrix(rotation) * np.asarray(scale, dtype=np.float64)[None, :]
    m[:3, 3] = translation
    return m


def decompose(m) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(translation, rotation quaternion, scale) of an affine matrix without shear."""
    m = np.asarray(m, dtype=np.float64)
    t = m[:3, 3].copy()
    s = np.linalg.norm(m[:3, :3], axis=0)
    r = m[:3, :3] / np.where(s > 0, s, 1.0)[None, :]
    if np.linalg.det(r) < 0:
        s[0] = -s[0]
        r[:, 0] = -r[:, 0]
    return t, matrix_to_quat(r), s


def look_at_rotation(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    """Quaternion that turns local -Z towards target - eye with local +Y near ``up``."""
    f = np.asarray(target, np.float64) - np.asarray(eye, np.float64)
    n = np.linalg.norm(f)
    if n == 0:
        raise ValueError("look-at: eye and target are the same point")
    f /= n
    upv = np.asarray(up, np.float64)
    if abs(np.dot(f, upv / np.linalg.norm(upv))) > 0.999:
        upv = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = np.cross(f, upv)
    x /= np.linalg.norm(x)
    y = np.cross(x, f)
    return matrix_to_quat(np.stack([x, y, -f], axis=1))


def perspective(yfov: float, aspect: float, znear: float, zfar: float) -> np.ndarray:
    f = 1.0 / np.tan(yfov / 2)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (zfar + znear) / (znear - zfar)
    m[2, 3] = 2 * zfar * znear / (znear - zfar)
    m[3, 2] = -1.0
    return m


def orthographic(half_w: float, half_h: float, znear: float, zfar: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 0] = 1.0 / half_w
    m[1, 1] = 1.0 / half_h
    m[2, 2] = -2.0 / (zfar - znear)
    m[2, 3] = -(zfar + znear) / (zfar - znear)
    return m
