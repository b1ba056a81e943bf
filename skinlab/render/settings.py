"""What a render is asked to do (beyond the scene itself)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from .compute import COMPUTE_CHOICES
from .options import Option, TechniqueSettings, option, technique_settings
from .techniques import DEFAULT_TECHNIQUE


@dataclass
class RenderSettings:
    """What a render is asked to do beyond the scene. The subsurface technique and its own settings
    are one value: ``technique`` is a technique's settings object (``TsdSettings(size=256)``), or a
    registered name for that technique's defaults (``"ssss"``); see :meth:`for_technique`."""

    width: int = 640
    height: int = 640
    shadow_size: int = 2048
    background: tuple[float, float, float] = (0.045, 0.045, 0.05)  # linear
    max_lights: int = 4
    # None: each material's own sss_model; else one of skinlab.scene.materials.SSS_MODELS for every material
    sss_model: str | None = None
    # how subsurface scattering is rendered: a registered technique's settings (skinlab/render/registry.py),
    # or its name for its defaults (a settings object after construction: `technique_options`)
    technique: TechniqueSettings | str = DEFAULT_TECHNIQUE
    # draw depth first, then shade each visible pixel once (skinlab/render/passes/forward.py)
    depth_prepass: bool = True
    # antialiasing by supersampling: the screen-space targets are N x the output size and each
    # output pixel is the box filter (mean) of its N x N samples of linear radiance, tone-mapped after
    # filtering (skinlab/shaders/passes/tonemap_supersample.frag); what the path-traced truth's box pixel filter does
    supersample: int = option(
        1,
        "antialiasing: shade N x N samples per output pixel and average them (box filter, before tone "
        "mapping); screen-space passes run at N x the size, texture-space passes and shadow maps do not change",
        "int",
        range=(1, 8),
        unit="samples per pixel side",
    )
    # interreflection (skinlab/render/bounce.py): light the scene's surfaces throw onto each other
    bounces: int = option(
        2,
        "interreflection: orders of light the scene's surfaces throw onto each other (0: off); gathered "
        "per vertex from cosine-weighted rays, for every technique",
        "int",
        range=(0, 8),
        unit="bounces",
    )
    bounce_rays: int = option(
        64,
        "interreflection: rays each vertex casts to find the surfaces it sees (more: less noise, a longer "
        "first frame after the geometry changes)",
        "int",
        range=(4, 4096),
        unit="rays per vertex",
    )
    # environment maps (skinlab/render/environment.py): what the scene hides of the map's light
    sky_occlusion: bool = option(
        True,
        "environment map: each surface receives the map's light less what the scene hides of it (from the "
        "interreflection's rays per vertex); false: every surface sees the whole map",
        "bool",
    )

    # compute shaders for the screen- and texture-space passes (skinlab/render/compute.py)
    compute: str = option(
        "auto",
        "compute shaders (GL 4.3) for the subsurface passes, tone mapping and the supersample filter: auto "
        "(per pass, the path measured faster on this kind of device), on (wherever the GL context offers "
        "them), off (fragment shaders); images agree to fp32 rounding",
        "choice",
        choices=COMPUTE_CHOICES,
    )

    def __post_init__(self) -> None:
        for name in ("width", "height", "shadow_size"):
            v = getattr(self, name)
            if not isinstance(v, int) or isinstance(v, bool) or v < 1 or v > 16384:
                raise ValueError(f"render setting {name}: expected an integer in [1, 16384], got {v!r}")
        for name, opt in self.options().items():
            setattr(self, name, opt.check(getattr(self, name), f"render setting {name}"))
        if max(self.width, self.height) * self.supersample > 16384:
            raise ValueError(
                f"render setting supersample: {self.width}x{self.height} at {self.supersample} x "
                f"{self.supersample} samples per pixel exceeds 16384 samples per side"
            )
        if self.sss_model is not None:
            from skinlab.scene.materials import SSS_MODELS

            if self.sss_model not in SSS_MODELS:
                raise ValueError(
                    f"render setting sss_model: expected one of {', '.join(SSS_MODELS)}, got {self.sss_model!r}"
                )
        if isinstance(self.technique, str):
            self.technique = technique_settings(self.technique)()
        elif not isinstance(self.technique, TechniqueSettings):
            raise ValueError(
                "render setting technique: expected a technique name or its settings, got " + repr(self.technique)
            )

    @classmethod
    def for_technique(cls, technique: str, width: int = 640, height: int = 640, **kw: Any) -> RenderSettings:
        """Settings for a technique by name; keywords are RenderSettings fields or the technique's
        own settings (``for_technique("tsd", 64, 64, shadow_size=256, size=128)``)."""
        st = technique_settings(technique)
        own = {f.name for f in dataclasses.fields(cls)}
        opts = {k: v for k, v in kw.items() if k not in own}
        unknown = set(opts) - set(st.options())
        if unknown:
            raise ValueError(
                f"render setting {sorted(unknown)[0]}: not a setting of technique {technique!r} "
                f"(its settings: {', '.join(st.options()) or 'none'})"
            )
        base = {k: v for k, v in kw.items() if k in own}
        return cls(width, height, **base, technique=st(**opts))

    @classmethod
    def options(cls) -> dict[str, Option]:
        """The render settings declared with :func:`option` (meaning, unit, default, range): the
        `skinlab render` options come from these."""
        return {f.name: f.metadata["option"] for f in dataclasses.fields(cls) if "option" in f.metadata}

    @property
    def technique_options(self) -> TechniqueSettings:
        """The technique's settings (``technique`` after construction, typed as such)."""
        assert isinstance(self.technique, TechniqueSettings)
        return self.technique

    @property
    def technique_name(self) -> str:
        return self.technique_options.technique

    @property
    def size(self) -> tuple[int, int]:
        """The output image's size in pixels."""
        return self.width, self.height

    @property
    def render_size(self) -> tuple[int, int]:
        """The screen-space targets' size: the output size times ``supersample``."""
        return self.width * self.supersample, self.height * self.supersample


def parse_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"--size: expected WIDTHxHEIGHT such as 640x480, got {text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise ValueError(f"--size: width and height must be in [1, 16384], got {text!r}")
    return w, h
