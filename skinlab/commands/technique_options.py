"""Command-line options of the registered techniques (skinlab/render/registry.py): `--technique` with
each technique's one-line description, and one option per field of each technique's settings
(``--<technique>-<field>``, plus any older spelling the field declares), all from the declarations."""

from __future__ import annotations

import argparse

from skinlab.commands.field_options import add_setting_option, option_flags, setting_value
from skinlab.declare import Field
from skinlab.render.options import TechniqueSettings
from skinlab.render.registry import DEFAULT_TECHNIQUE, get_technique, techniques


def _flags(technique: str, field: Field) -> list[str]:
    return option_flags(field, prefix=f"{technique}_")


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
        for name, o in opts.items():
            add_setting_option(group, o, _dest(t.name, name), _flags(t.name, o))


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
            flag = _flags(t.name, o)[0]
            if t is not chosen:
                raise ValueError(f"{flag}: a setting of technique {t.name}, but --technique is {chosen.name}")
            values[name] = setting_value(o, raw, flag)
    return chosen.settings_type(**values)


def _render_dest(field: str) -> str:
    return f"render_opt__{field}"


def add_render_options(parser: argparse.ArgumentParser) -> None:
    """One option per render setting declared for the command line (RenderSettings.options():
    ``--shadow-size N``, ``--supersample N``, ``--sss MODEL``, ...), help and checks from the declaration."""
    from skinlab.render.settings import RenderSettings

    for name, o in RenderSettings.options().items():
        add_setting_option(parser, o, _render_dest(name))


def render_options_from_args(args) -> dict:
    """The declared render settings given on the command line (keywords for RenderSettings); a bad
    value is an error naming the option."""
    from skinlab.render.settings import RenderSettings

    values = {}
    for name, o in RenderSettings.options().items():
        raw = getattr(args, _render_dest(name), None)
        if raw is not None:
            values[name] = setting_value(o, raw, option_flags(o)[0])
    return values


def add_frame_options(parser: argparse.ArgumentParser) -> None:
    """The frame's settings that `skinlab render` and `skinlab view` share, each declared once in
    RenderSettings (:func:`add_render_options`: --shadow-size, --sss, --supersample, --bounces, ...) or
    a technique's settings (:func:`add_technique_options`: --technique and its options)."""
    add_render_options(parser)
    add_technique_options(parser)  # an option of another technique than --technique is an error naming it


def render_settings_from_args(args, w: int, h: int):
    """RenderSettings from the options of :func:`add_frame_options` (errors name the option)."""
    from skinlab.render.settings import RenderSettings

    return RenderSettings(w, h, technique=technique_from_args(args), **render_options_from_args(args))
