"""The one source of numeric constants shared by the NumPy references and the GLSL shaders.

`GLSL_CONSTANTS` is turned into the virtual include file ``skinlab/constants.glsl`` by
:func:`glsl_header`; shaders never spell these numbers themselves.
"""
from __future__ import annotations

import math

PI = math.pi
INV_PI = 1.0 / math.pi

# Smallest GGX alpha (= roughness^2). Roughness 0 is a mirror; alpha is clamped so that the
# D term stays finite in fp32 (peak 1/(pi alpha^2) ~ 3.2e5 at alpha=1e-3).
MIN_GGX_ALPHA = 1.0e-3
# Cosines are clamped to at least this before they divide anything (grazing angles n.v -> 0).
MIN_COS = 1.0e-4
# Dielectric F0 for specular = 0.5 (Burley 2012: specular 0.5 <=> F0 = 0.04); F0 = 0.08 * specular.
SPECULAR_F0_SCALE = 0.08

# sRGB transfer function (IEC 61966-2-1)
SRGB_LINEAR_THRESHOLD = 0.0031308
SRGB_ENCODED_THRESHOLD = 0.04045

# Point lights: distances are clamped to at least this (metres) before the inverse square.
MIN_LIGHT_DISTANCE_M = 1.0e-3

# Shadow map depth bias in normalised light depth units (slope-scaled part added in shader).
SHADOW_BIAS = 0.0015

GLSL_CONSTANTS: dict[str, float] = {
    "PI": PI,
    "INV_PI": INV_PI,
    "MIN_GGX_ALPHA": MIN_GGX_ALPHA,
    "MIN_COS": MIN_COS,
    "SPECULAR_F0_SCALE": SPECULAR_F0_SCALE,
    "SRGB_LINEAR_THRESHOLD": SRGB_LINEAR_THRESHOLD,
    "SRGB_ENCODED_THRESHOLD": SRGB_ENCODED_THRESHOLD,
    "SHADOW_BIAS": SHADOW_BIAS,
    "MIN_LIGHT_DISTANCE_M": MIN_LIGHT_DISTANCE_M,
}


def register(name: str, value: float) -> float:
    """Add a constant to the shared table (for optics modules defined elsewhere) and return it."""
    if name in GLSL_CONSTANTS and GLSL_CONSTANTS[name] != value:
        raise ValueError(f"constant {name} registered twice with different values")
    GLSL_CONSTANTS[name] = float(value)
    return float(value)


def glsl_header() -> str:
    """GLSL source for the shared constants (included as "skinlab/constants.glsl")."""
    lines = ["// Generated from scene/optics/constants.py - do not edit."]
    for name, value in GLSL_CONSTANTS.items():
        lines.append(f"const float {name} = {float(value)!r};")
    return "\n".join(lines) + "\n"
