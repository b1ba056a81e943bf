"""What a render is asked to do (beyond the scene itself)."""

from __future__ import annotations

from dataclasses import dataclass

TECHNIQUES = ("tsd", "exact", "ssss", "tint")


@dataclass
class RenderSettings:
    width: int = 640
    height: int = 640
    shadow_size: int = 2048
    background: tuple[float, float, float] = (0.045, 0.045, 0.05)  # linear
    max_lights: int = 4
    # None: each material's own sss_model; else one of scene.materials.SSS_MODELS for every material
    sss_model: str | None = None
    # how subsurface scattering is rendered (TECHNIQUES): texture-space diffusion with the Gaussian
    # fit ("tsd", default), brute-force texture-space convolution with the exact profile ("exact",
    # the slow image reference), screen-space separable SSS ("ssss", Jimenez et al.), or the
    # per-pixel profile tint without convolution ("tint", the original study's baseline)
    technique: str = "tsd"
    tsd_taps: int | None = None  # None: from each blur's width in texels; else a fixed odd count (7..31)
    ssss_taps: int = 17  # screen-space kernel samples: 11, 17 or 25 (Jimenez presets)
    # texture-space diffusion defaults from the accuracy/time ledger (docs/ledger.md): the cheapest
    # setting within 1 % image error of the exact reference on the head and the bunny
    tsd_size: int = 512  # irradiance texels per side
    tsd_albedo_mix: float = 0.5  # pre-/post-scatter texturing: albedo^mix before the blur
    tsd_gaussians: int = 6  # K: Gaussians fitted to the profile
    translucency: bool = True  # light through thin parts (needs a shadow-casting light)

    def __post_init__(self) -> None:
        for name in ("width", "height", "shadow_size"):
            v = getattr(self, name)
            if not isinstance(v, int) or v < 1 or v > 16384:
                raise ValueError(f"render setting {name}: expected an integer in [1, 16384], got {v!r}")
        if self.sss_model is not None:
            from scene.materials import SSS_MODELS

            if self.sss_model not in SSS_MODELS:
                raise ValueError(
                    f"render setting sss_model: expected one of {', '.join(SSS_MODELS)}, got {self.sss_model!r}"
                )
        if self.technique not in TECHNIQUES:
            raise ValueError(
                f"render setting technique: expected one of {', '.join(TECHNIQUES)}, got {self.technique!r}"
            )
        if self.tsd_taps is not None and (
            not isinstance(self.tsd_taps, int) or self.tsd_taps % 2 == 0 or not 7 <= self.tsd_taps <= 31
        ):
            raise ValueError(
                f"render setting tsd_taps: expected an odd integer in [7, 31] or None, got {self.tsd_taps!r}"
            )
        if not isinstance(self.ssss_taps, int) or self.ssss_taps % 2 == 0 or not 3 <= self.ssss_taps <= 63:
            raise ValueError(f"render setting ssss_taps: expected an odd integer in [3, 63], got {self.ssss_taps!r}")
        if not isinstance(self.tsd_size, int) or not 16 <= self.tsd_size <= 8192:
            raise ValueError(f"render setting tsd_size: expected an integer in [16, 8192], got {self.tsd_size!r}")
        if not isinstance(self.tsd_gaussians, int) or not 1 <= self.tsd_gaussians <= 6:
            raise ValueError(f"render setting tsd_gaussians: expected an integer in [1, 6], got {self.tsd_gaussians!r}")
        if not 0.0 <= float(self.tsd_albedo_mix) <= 1.0:
            raise ValueError(f"render setting tsd_albedo_mix: expected a number in [0, 1], got {self.tsd_albedo_mix!r}")

    @property
    def size(self) -> tuple[int, int]:
        return self.width, self.height


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--size: expected WIDTHxHEIGHT such as 640x480, got {text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"--size: width and height must be in [1, 16384], got {text!r}")
    return w, h
