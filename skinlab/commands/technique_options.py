"""Command-line options of the registered techniques (skinlab/render/registry.py): `--technique` with
each technique's one-line description, and one option per field of each technique's settings
(``--<technique>-<field>``, plus any older spelling the field declares), all from the declarations."""

from __future__ import annotations

import argparse

from skinlab.render.options import TechniqueSettings
from skinlab.render.registry import DEFAULT_TECHNIQUE, get_technique, techniques


def _flags(technique: str, field: str, extra: tuple[str, ...]) -> list[str]:
    flags = [f"--{technique}-{field.replace('_', '-')}"]
    return flags + [f for f in extra if f not in flags]


def _dest(technique: str, field: str) -> str:
    return f"technique_opt__{technique}__{field}"


def add_technique_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--technique",
        choices=[t.name for t in techniques()],
        default=DEFAULT_TECHNIQUE,
        help="how subsurface scattering is rendered (default: %(default)s): "
        + "; ".join(f"{t.name}: {t.description}" for t in techniques()),
    )
    for t in techniques():
        opts = t.settings_type.options()
        if not opts:
            continue
        group = parser.add_argument_group(f"technique {t.name} ({t.description})")
        defaults = t.settings_type.defaults()
        for name, o in opts.items():
            flags = _flags(t.name, name, o.flags)
            kw = dict(dest=_dest(t.name, name), default=None, help=o.help(defaults[name]))
            if o.kind == "bool":
                group.add_argument(*flags, action=argparse.BooleanOptionalAction, **kw)
            elif o.kind == "choice":
                group.add_argument(*flags, choices=o.choices, **kw)
            else:
                group.add_argument(*flags, type=str, metavar="N" if o.kind == "int" else "X", **kw)


def technique_from_args(args) -> TechniqueSettings:
    """The chosen technique's settings from the parsed options; an option of another technique is
    an error naming it (it would have no effect)."""
    chosen = get_technique(args.technique)
    values = {}
    for t in techniques():
        for name, o in t.settings_type.options().items():
            raw = getattr(args, _dest(t.name, name), None)
            if raw is None:
                continue
            flag = _flags(t.name, name, o.flags)[0]
            if t is not chosen:
                raise ValueError(f"{flag}: a setting of technique {t.name}, but --technique is {chosen.name}")
            values[name] = o.check(_parse(raw, o.kind, flag, o), flag)
    return chosen.settings_type(**values)


def _parse(raw, kind: str, flag: str, o):
    if kind in ("bool", "choice") or not isinstance(raw, str):
        return raw
    try:
        return int(raw) if kind == "int" else float(raw)
    except ValueError:
        raise ValueError(f"{flag}: expected {o.expected()}, got {raw!r}") from None


def _render_dest(field: str) -> str:
    return f"render_opt__{field}"


def add_render_options(parser: argparse.ArgumentParser) -> None:
    """One option per render setting declared with ``option`` (RenderSettings.options():
    ``--supersample N``), help and checks from the declaration."""
    from skinlab.render.settings import RenderSettings

    for name, o in RenderSettings.options().items():
        flag = "--" + name.replace("_", "-")
        default = RenderSettings.__dataclass_fields__[name].default
        kw = dict(dest=_render_dest(name), default=None, help=o.help(default))
        if o.kind == "bool":
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, **kw)
        elif o.kind == "choice":
            parser.add_argument(flag, choices=o.choices, **kw)
        else:
            parser.add_argument(flag, type=str, metavar="N" if o.kind == "int" else "X", **kw)


def render_options_from_args(args) -> dict:
    """The declared render settings given on the command line (keywords for RenderSettings); a bad
    value is an error naming the option."""
    from skinlab.render.settings import RenderSettings

    values = {}
    for name, o in RenderSettings.options().items():
        raw = getattr(args, _render_dest(name), None)
        if raw is not None:
            flag = "--" + name.replace("_", "-")
            values[name] = o.check(_parse(raw, o.kind, flag, o), flag)
    return values


def add_frame_options(parser: argparse.ArgumentParser) -> None:
    """The frame's settings that `skinlab render` and `skinlab view` share, each declared once here or
    in RenderSettings: --shadow-size, the declared render settings (:func:`add_render_options`:
    --supersample, --bounces, ...), --sss and the technique's options (:func:`add_technique_options`)."""
    from skinlab.scene.materials import SSS_MODELS

    parser.add_argument(
        "--shadow-size", type=int, default=2048, help="shadow map texels per side, 1-16384 (default 2048)"
    )
    add_render_options(parser)  # --supersample N, --bounces N, ... from RenderSettings' declarations
    parser.add_argument(
        "--sss",
        choices=SSS_MODELS,
        default=None,
        help="subsurface model for every material (default: each material's own sss_model)",
    )
    add_technique_options(parser)  # an option of another technique than --technique is an error naming it


def render_settings_from_args(args, w: int, h: int):
    """RenderSettings from the options of :func:`add_frame_options` (errors name the option)."""
    from skinlab.render.settings import RenderSettings

    return RenderSettings(
        w,
        h,
        shadow_size=args.shadow_size,
        sss_model=args.sss,
        technique=technique_from_args(args),
        **render_options_from_args(args),
    )
