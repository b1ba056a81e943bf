"""The uniforms of skinlab/shaders/lib/sss_boundary.glsl for one mesh: how light enters and leaves its
material's medium (skinlab/scene/optics/boundary.py). The forward pass and the passes that gather light
into a profile (texture-space irradiance) bind them; every technique shares them, so only the
convolution differs between techniques."""

from __future__ import annotations

import numpy as np

from skinlab.cache import table
from skinlab.gl.uniforms import set_array, set_uniforms
from skinlab.scene.optics.boundary import ANGULAR_NODES, MS_REST_NODES, BoundaryTables, boundary_tables, ms_rest_table
from skinlab.scene.optics.fresnel import fdr
from skinlab.scene.optics.material_medium import material_medium, subsurface_albedo
from skinlab.scene.optics.oblique import single_pair_rate
from skinlab.scene.optics.similarity import real_albedo, real_mfp
from skinlab.scene.optics.slab import LN_FLOOR, SLAB_MU_NODES, SLAB_TAU_NODES, slab_decay, slab_exit_tables, slab_table

_ZERO_TABLE = np.zeros((ANGULAR_NODES, 3))
_MS_REST_ROWS = MS_REST_NODES * MS_REST_NODES
_ZERO_REST = np.zeros((_MS_REST_ROWS, 3))
_SLAB_ROWS = SLAB_MU_NODES * SLAB_TAU_NODES
_DARK_SLAB = np.full((_SLAB_ROWS, 3), LN_FLOOR)
_DARK_NORM = np.full((SLAB_TAU_NODES, 3), LN_FLOOR)
_ZERO_H = np.zeros((_SLAB_ROWS, 3))
_UNIT_AB = np.concatenate([np.ones((SLAB_TAU_NODES, 3)), np.zeros((SLAB_TAU_NODES, 3))])


@table(disk=True, maxsize=256)
def _slab_tables(alpha: tuple, colour: tuple, eta: float):
    """The slab transmittance table (ln T per unit colour) and the exit factor's tables of the light
    that comes through (skinlab/scene/optics/slab.py slab_exit_tables: ln T_d, h, A and B)."""
    table = slab_table(np.array(alpha), np.array(colour))
    return table, slab_exit_tables(np.array(alpha), table, eta)


def material_boundary(material) -> BoundaryTables | None:
    """The tables of a material that scatters below its surface; None for one that does not."""
    if material is None or not material.has_subsurface:
        return None
    medium = material_medium(material.values)
    colour = subsurface_albedo(material.values)  # what the frame's subsurface albedo stands for, on average
    return boundary_tables(medium.alpha_arr, colour, medium.eta, boundary_ggx_alpha(material))


def material_ms_rest(material) -> np.ndarray:
    """The non-separable rest of the multiple-scattering BRDF of a material that scatters
    (skinlab/scene/optics/boundary.py ms_rest_table: (N, N, 3), zero at eta > 1)."""
    medium = material_medium(material.values)
    return ms_rest_table(medium.alpha_arr, subsurface_albedo(material.values), medium.eta, boundary_ggx_alpha(material))


def boundary_defines(material) -> dict:
    """The forward pass's variant for `material`'s boundary (None: a mesh shaded without its medium):
    SSS_MS_REST where its multiple scattering's non-separable rest is not all zero
    (lib/sss_boundary.glsl sss_ms_rest; zero at eta > 1); without it the rest is compiled out, as it
    adds 0 (a software rasteriser runs a branch's arithmetic even where no fragment takes it,
    docs/tsd.md "Fifth round")."""
    if material_boundary(material) is None:
        return {}
    return {"SSS_MS_REST": 1} if np.any(material_ms_rest(material) != 0) else {}


def boundary_data(material) -> None:
    """Make (or read) everything :func:`bind_boundary` binds for `material`: its boundary tables and
    its slab tables (both memoised: a later bind finds them)."""
    if material_boundary(material) is not None:
        medium = material_medium(material.values)
        colour = subsurface_albedo(material.values)
        _slab_tables(tuple(medium.alpha_arr), tuple(float(x) for x in colour), float(medium.eta))
        material_ms_rest(material)


def prefetch_boundaries(meshes, settings) -> None:
    """Start making the boundary and slab tables of every visible scattering material on a worker
    thread (skinlab/cache.py in_background) while the frame is planned: on a first run they are
    0.3 s of NumPy work in large arrays (the GIL released) that the plan's own GIL-bound work (UV
    seams) can overlap; the frame's first bind waits for them (the tables are memoised: never made
    twice). Nothing to make when they are cached."""
    from skinlab.cache import in_background

    from .scattering import effective_material

    seen: set[int] = set()
    for node in meshes:
        material = effective_material(node, settings)
        if id(material) not in seen and material.has_subsurface:
            seen.add(id(material))
            in_background(boundary_data, material)


def single_scattering_factor(material, tables: BoundaryTables) -> np.ndarray:
    """u_sss_single: Jensen's term per unit subsurface albedo with the medium's real single-scattering
    albedo (similarity: a = a' / (1 - g + g a'), skinlab/scene/optics/similarity.py); g = 0 keeps the
    tables' a' / A_colour."""
    g = float(material.values.get("subsurface_scatter_anisotropy", 0.0))
    if g == 0.0:
        return tables.single
    reduced = material_medium(material.values).alpha_arr
    ratio = np.where(reduced > 0, real_albedo(reduced, g) / np.where(reduced > 0, reduced, 1.0), 0.0)
    return tables.single * ratio


def real_extinction(medium, g: float) -> np.ndarray:
    """u_sss_sigma_t: the real extinction 1 / l per channel, per mm, of the reduced `medium`
    (skinlab/scene/optics/material_medium.py) of anisotropy g (its mean free path turned into the real
    one by similarity, skinlab/scene/optics/similarity.py; 0 where there is no scattering). The near
    light's single scattering needs it (lib/sss_near_single.glsl)."""
    mfp = real_mfp(medium.mfp_arr, medium.alpha_arr, g)
    return np.where(mfp > 0, 1.0 / np.where(mfp > 0, mfp, 1.0), 0.0)


def boundary_ggx_alpha(material) -> float:
    """GGX alpha of the material's boundary, roughness^2 (as the truth exporter's rough dielectric)."""
    return float(material["roughness"]) ** 2


def bind_boundary(prog, material) -> None:
    """Write the u_sss_* boundary uniforms for `material` (zeros: no subsurface term)."""
    t = material_boundary(material)
    if t is None:
        set_array(prog, "u_sss_entry", _ZERO_TABLE, ANGULAR_NODES)
        set_array(prog, "u_sss_exit", _ZERO_TABLE, ANGULAR_NODES)
        set_array(prog, "u_sss_single_ambient", _ZERO_TABLE, ANGULAR_NODES)
        set_array(prog, "u_sss_ms_rest", _ZERO_REST, _MS_REST_ROWS)
        zero = (0.0, 0.0, 0.0)
        set_uniforms(
            prog,
            {
                "u_sss_entry_diffuse": zero,
                "u_sss_single": zero,
                "u_sss_eta": 1.0,
                "u_sss_g": 0.0,
                "u_sss_ms_rest_on": 0.0,
            },
        )
        set_array(prog, "u_sss_slab", _DARK_SLAB, _SLAB_ROWS)
        set_array(prog, "u_sss_slab_norm", _DARK_NORM, SLAB_TAU_NODES)
        set_array(prog, "u_sss_slab_h", _ZERO_H, _SLAB_ROWS)
        set_array(prog, "u_sss_slab_ab", _UNIT_AB, 2 * SLAB_TAU_NODES)
        set_uniforms(
            prog,
            {
                "u_sss_mfp": zero,
                "u_sss_sigma_t": zero,
                "u_sss_slab_decay": zero,
                "u_sss_slab_out": 1.0,
                "u_sss_single_ramp": zero,
            },
        )
        return
    set_array(prog, "u_sss_entry", t.entry, ANGULAR_NODES)
    set_array(prog, "u_sss_exit", t.exit, ANGULAR_NODES)
    set_array(prog, "u_sss_single_ambient", t.single_ambient, ANGULAR_NODES)
    rest = material_ms_rest(material)
    set_array(prog, "u_sss_ms_rest", rest.reshape(_MS_REST_ROWS, 3), _MS_REST_ROWS)
    set_uniforms(prog, {"u_sss_ms_rest_on": 1.0 if np.any(rest != 0) else 0.0})
    g = float(material.values.get("subsurface_scatter_anisotropy", 0.0))
    single = single_scattering_factor(material, t)
    set_uniforms(
        prog, {"u_sss_entry_diffuse": t.entry_diffuse, "u_sss_single": single, "u_sss_eta": t.eta, "u_sss_g": g}
    )
    medium = material_medium(material.values)
    colour = subsurface_albedo(material.values)
    table, (norm, h, ab) = _slab_tables(tuple(medium.alpha_arr), tuple(float(x) for x in colour), float(medium.eta))
    set_array(prog, "u_sss_slab", table, _SLAB_ROWS)
    set_array(prog, "u_sss_slab_norm", norm, SLAB_TAU_NODES)
    set_array(prog, "u_sss_slab_h", h, _SLAB_ROWS)
    set_array(prog, "u_sss_slab_ab", ab, 2 * SLAB_TAU_NODES)
    out = 1.0 - float(fdr(medium.eta)) if medium.eta > 1.0 else 1.0
    set_uniforms(
        prog,
        {
            "u_sss_mfp": medium.mfp_arr,
            "u_sss_sigma_t": real_extinction(medium, g),
            "u_sss_slab_decay": slab_decay(medium.alpha_arr),
            "u_sss_single_ramp": single_pair_rate(medium.mfp_arr),
            "u_sss_slab_out": out,
        },
    )
