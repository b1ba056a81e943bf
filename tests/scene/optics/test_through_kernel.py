"""The transfer through the medium (skinlab/scene/optics/through_kernel.py): a flat slab lit evenly on
its far face transmits the exact slab's light; the light gathered comes only from the part's own faces
and falls with the distance through it; hard cases stay finite."""

import numpy as np
import pytest

from skinlab.scene.graph import MeshNode
from skinlab.scene.mesh import Mesh
from skinlab.scene.optics import through_kernel as tk
from skinlab.scene.optics.material_medium import material_medium
from skinlab.scene.optics.slab import slab_table, slab_through
from tests.tsd_scenes import skin

N = 40  # quads per side


def plate(n, z, facing, half=1.0):
    u, v = np.meshgrid(np.linspace(-half, half, n + 1), np.linspace(-half, half, n + 1), indexing="ij")
    p = np.stack([u, v, np.full_like(u, z)], -1).reshape(-1, 3)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    if facing > 0:
        faces = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    else:
        faces = np.concatenate([np.stack([a, c, b], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])
    return p, faces, np.tile([0.0, 0.0, float(facing)], (len(p), 1))


def slab_node(thickness, material, n=N, half=1.0):
    """Two plates, the front (z = 0, facing +z) and the back (z = -thickness, facing -z), one mesh."""
    p0, f0, n0 = plate(n, 0.0, 1, half)
    p1, f1, n1 = plate(n, -thickness, -1, half)
    mesh = Mesh("slab", np.concatenate([p0, p1]), np.concatenate([f0, f1 + len(p0)]), np.concatenate([n0, n1]))
    return MeshNode("slab", mesh, material)


def centre(n=N):
    return (n // 2) * (n + 1) + n // 2


def exact(material, d_mm):
    med = material_medium(material.values)
    table = slab_table(med.alpha_arr, material["subsurface_color"])
    return slab_through(1.0, d_mm, table, med.mfp_arr, med.alpha_arr, med.eta)


@pytest.mark.parametrize("d_mm", [1.0, 3.0, 6.0])
def test_flat_slab_lit_evenly_transmits_the_exact_slabs_light(d_mm):
    """Entering light 1 on every vertex of the far face, 0 on the near one: the near face's middle
    receives the exact slab transmittance (slab.py slab_through) within 4 % per channel (64 rays, a
    slab 20 times as wide as thick). Its own face sends nothing to it."""
    mat = skin(radius=(8.0, 4.0, 2.0))
    mm = 20.0  # mm per unit
    node = slab_node(d_mm / mm, mat, half=10.0 * d_mm / mm)
    rows = tk.medium_rows(node, mat, mm, 64)
    v = len(node.mesh.positions)
    entering = np.zeros((v, 3))
    entering[v // 2 :] = 1.0  # the back plate
    got = tk.gather(rows, entering)[centre()]
    np.testing.assert_allclose(got, exact(mat, d_mm), rtol=0.04)
    front_only = np.zeros((v, 3))
    front_only[: v // 2] = 1.0
    assert tk.gather(rows, front_only)[centre()].max() == 0.0


def test_light_falls_with_the_distance_through_and_blue_falls_fastest():
    mat = skin(radius=(8.0, 4.0, 2.0))
    out = []
    for d_mm in (1.0, 4.0):
        node = slab_node(d_mm / 20.0, mat, half=0.5)
        rows = tk.medium_rows(node, mat, 20.0, 32)
        e = np.zeros((len(node.mesh.positions), 3))
        e[len(e) // 2 :] = 1.0
        out.append(tk.gather(rows, e)[centre()])
    thin, thick = out
    assert np.all(thick < thin)
    assert thick[2] / thin[2] < thick[0] / thin[0]


def test_rows_are_finite_for_hard_cases():
    """A medium that does not scatter in one channel (mean free path 0 there: nothing goes through in
    it), a sheet of no thickness (the plates on one another) and a single plate (rays meet nothing):
    finite, non-negative, no light where no medium carries it."""
    mat = skin(radius=(8.0, 0.0, 2.0))
    for node in (slab_node(0.05, mat, n=8), slab_node(0.0, mat, n=8)):
        rows = tk.medium_rows(node, mat, 20.0, 16)
        assert np.all(np.isfinite(rows.weights)) and np.all(rows.weights >= 0.0)
        assert np.all(np.isfinite(rows.depth_mm))
    p, f, nrm = plate(8, 0.0, 1)
    single = MeshNode("plate", Mesh("plate", p, f, nrm), mat)
    rows = tk.medium_rows(single, mat, 20.0, 16)
    assert len(rows.senders) == 0
    assert np.all(tk.gather(rows, np.ones((len(p), 3))) == 0.0)


def test_rays_must_be_a_positive_integer():
    mat = skin()
    with pytest.raises(ValueError, match="through kernel rays"):
        tk.through_records(slab_node(0.1, mat, n=2), 0)
