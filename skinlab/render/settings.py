"""What a render is asked to do (beyond the scene itself)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from skinlab.declare import Field, declared_fields, option
from skinlab.scene.materials import SSS_MODELS

from .compute import COMPUTE_CHOICES
from .options import TechniqueSettings, technique_settings
from .techniques import DEFAULT_TECHNIQUE

MAX_SIZE = 16384  # pixels or texels per side of any target


@dataclass
class RenderSettings:
    """What a render is asked to do beyond the scene. The subsurface technique and its own settings
    are one value: ``technique`` is a technique's settings object (``TsdSettings(size=256)``), or a
    registered name for that technique's defaults (``"ssss"``); see :meth:`for_technique`.
    Every other field is declared with :func:`option` (:meth:`fields`); those with ``cli`` are the
    options of `skinlab render` and `skinlab view` (:meth:`options`), those with ``panel`` the viewer's
    widgets (:meth:`panel_options`)."""

    # the output's size: `--size WIDTHxHEIGHT` (parse_size), the viewer's window
    width: int = option(640, "output image width", "int", range=(1, MAX_SIZE), unit="pixels", cli=False, panel=False)
    height: int = option(640, "output image height", "int", range=(1, MAX_SIZE), unit="pixels", cli=False, panel=False)
    shadow_size: int = option(
        2048,
        "shadow map texels per side (each shadow-casting light's depth map, and its distance map)",
        "int",
        range=(1, MAX_SIZE),
        unit="texels",
        panel=False,  # a slider over 1-16384 texels helps no one; the command line sets it
    )
    shadow_fit: bool = option(
        True,
        "a second shadow map per light fitted to what the camera sees, where that makes its texels at "
        "least twice as fine (close-ups: skinlab/render/shadow_fit.py); off: one map over the whole scene",
        "bool",
        panel=False,
    )
    entry_spread: bool = option(
        True,
        "light entering a scattering medium at an angle entered upstream by an exponential distance per "
        "channel: its shadow spread over three lookups (the texture-space irradiance, the forward hooks "
        "that gather their light) and single scattering's over two (one more per light in the forward "
        "pass; skinlab/scene/optics/oblique.py); off: one lookup at the mean entry point",
        "bool",
        panel=False,
    )
    single_through: bool = option(
        True,
        "single scattering of a shadow-casting directional light along its path through the medium as the "
        "distance map gives it (where the frame has distance maps: a technique's translucency on): more light "
        "near a convex part's terminator and past it, the flat medium's term on a flat part "
        "(lib/sss_single_through.glsl); off: the flat medium's term everywhere",
        "bool",
        panel=False,
    )
    background: tuple[float, float, float] = option(
        (0.045, 0.045, 0.05),
        "the colour behind the meshes where no environment map is drawn",
        "color",
        range=(0.0, 1.0e4),
        unit="linear RGB",
        cli=False,
        panel=False,
    )
    max_lights: int = option(
        4,
        "lights shaded per frame: the scene's first ones",
        "int",
        range=(1, 64),
        unit="lights",
        cli=False,
        panel=False,
    )
    # the viewer's M key cycles it (its own key, not a panel widget)
    sss_model: str | None = option(
        None,
        "subsurface model for every material",
        "choice",
        choices=SSS_MODELS,
        none="each material's own sss_model",
        flags=("--sss",),
        panel=False,
    )
    # how subsurface scattering is rendered: a registered technique's settings (skinlab/render/registry.py),
    # or its name for its defaults (a settings object after construction: `technique_options`)
    technique: TechniqueSettings | str = DEFAULT_TECHNIQUE
    depth_prepass: bool = option(
        True,
        "draw depth first, then shade each visible pixel once (skinlab/render/passes/forward.py)",
        "bool",
        cli=False,
        panel=False,
    )
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
    # light through thin parts (skinlab/render/through_kernel.py): the transfer through the medium
    through_kernel: bool = option(
        False,
        "light through thin parts gathered per vertex from rays into the medium (the diffusion's transmission "
        "kernel from the part's other faces, for every technique with translucency; meshes finer than two "
        "diffusion lengths); false: the distance map's slab along the light at each point "
        "(docs/ground-truth.md compares them)",
        "bool",
    )
    through_rays: int = option(
        64,
        "light through thin parts: rays each vertex casts into the medium (more: less noise, a longer first "
        "frame after the geometry changes)",
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
        for name, decl in self.fields().items():
            setattr(self, name, decl.check(getattr(self, name), f"render setting {name}"))
        if max(self.width, self.height) * self.supersample > MAX_SIZE:
            raise ValueError(
                f"render setting supersample: {self.width}x{self.height} at {self.supersample} x "
                f"{self.supersample} samples per pixel exceeds {MAX_SIZE} samples per side"
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
    def fields(cls) -> dict[str, Field]:
        """Every render setting but the technique, as declared with :func:`option` (meaning, unit,
        default, range): construction checks each."""
        return declared_fields(cls)

    @classmethod
    def options(cls) -> dict[str, Field]:
        """The settings `skinlab render` and `skinlab view` take as options (``--shadow-size``,
        ``--supersample``, ``--sss``, ...: skinlab/commands/field_options.py)."""
        return {name: f for name, f in cls.fields().items() if f.cli}

    @classmethod
    def panel_options(cls) -> dict[str, Field]:
        """The settings the viewer's panel offers as widgets (skinlab/viewer/panel.py)."""
        return {name: f for name, f in cls.fields().items() if f.panel}

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
    if not (1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE):
        raise ValueError(f"--size: width and height must be in [1, {MAX_SIZE}], got {text!r}")
    return w, h
