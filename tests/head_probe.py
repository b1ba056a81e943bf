"""Geometric landmarks on the head scan, for render tests (lips, cheek)."""

import numpy as np


def landmarks(scene):
    (head,) = scene.mesh_nodes()
    m = head.world_matrix
    p = head.mesh.positions @ m[:3, :3].T + m[:3, 3]
    nose = p[np.argmax(p[:, 2])]

    def frontmost(sel):
        idx = np.flatnonzero(sel)
        return p[idx[np.argmax(p[idx, 2])]]

    lips = frontmost((np.abs(p[:, 0] - nose[0]) < 0.25) & (p[:, 1] < nose[1] - 0.5) & (p[:, 1] > nose[1] - 1.3))
    cheek = frontmost((np.abs(p[:, 0] - nose[0] - 1.0) < 0.15) & (np.abs(p[:, 1] - nose[1] + 0.3) < 0.15))
    chin = frontmost((np.abs(p[:, 0] - nose[0]) < 0.25) & (p[:, 1] < nose[1] - 1.6) & (p[:, 1] > nose[1] - 2.4))
    return {"nose": nose, "lips": lips, "cheek": cheek, "chin": chin}


def project(scene, point, size):
    w, h = size
    cam = scene.camera
    clip = cam.projection_matrix(w / h) @ cam.view_matrix() @ np.append(point, 1.0)
    ndc = clip[:3] / clip[3]
    return int((ndc[0] * 0.5 + 0.5) * w), int((1 - (ndc[1] * 0.5 + 0.5)) * h)  # column, row (top first)


def redness(img, point_px, r=2):
    x, y = point_px
    patch = img[y - r : y + r + 1, x - r : x + r + 1, :3].astype(np.float64)
    rgb = patch.reshape(-1, 3).mean(0)
    return rgb[0] / max(rgb[1], 1e-6)
