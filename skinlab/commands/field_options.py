"""Command-line options made from declarations (skinlab/declare.py ``Field``): the option's spelling,
help (meaning, values, default with its unit) and choices come from the Field, and so do the checks of
the value given (an error naming the option and what was expected).

Two uses: a *setting* (a render or technique setting, a scene-file key) is None when not given, so
that the declaration's own default (or the scene's value) holds: :func:`add_setting_option` and
:func:`setting_value`; a command's *own* option (``--out``, ``--frames``) has its declared default on
the parsed arguments: :func:`add_command_options`, checked by :func:`check_command_options` (into a
mutually exclusive group too; a colour/vec kind is typed R,G,B; an integer may be typed 1e5). A
setting a command takes with a deliberately different default is :func:`own_default`: its help says so."""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Callable, Iterable
from typing import Any

from skinlab.declare import VECTOR_SIZES, Field

_METAVAR = {"int": "N", "float": "X", "color": "R,G,B", "vec3": "X,Y,Z", "vec2": "U,V"}

# an option two commands share with one meaning (`skinlab render --size`, `skinlab demo --size`)
IMAGE_SIZE = Field("size", "string", "640x640", doc="image size WIDTHxHEIGHT in pixels")


def option_flags(f: Field, prefix: str = "") -> list[str]:
    """``--<prefix><name>`` (underscores as dashes) and the other spellings the field declares."""
    main = "--" + (prefix + f.name).replace("_", "-")
    return [main, *(x for x in f.flags if x != main)]


def _help(text: str) -> str:
    return text.replace("%", "%%")  # argparse formats help with %


def add_setting_option(
    parser, f: Field, dest: str, flags: list[str] | None = None, help: str | None = None, metavar: str | None = None
) -> None:
    """One option for a declared setting; its value is None unless given (:func:`setting_value`)."""
    flags = flags or option_flags(f)
    kw: dict[str, Any] = dict(dest=dest, default=None, help=_help(help or f.help()))
    if f.kind == "bool":
        parser.add_argument(*flags, action=argparse.BooleanOptionalAction, **kw)
    elif f.kind == "choice":
        parser.add_argument(*flags, choices=f.choices, **kw)
    else:
        parser.add_argument(*flags, type=str, metavar=metavar or _METAVAR.get(f.kind, f.name.upper()), **kw)


def setting_value(f: Field, raw: Any, flag: str) -> Any:
    """A given option's value, checked against its declaration (errors name the option); None: not given."""
    if raw is None:
        return None
    if isinstance(raw, str) and f.kind in ("int", "float"):
        try:
            raw = int(raw) if f.kind == "int" else float(raw)
        except ValueError:
            raise ValueError(f"{flag}: expected {f.expected()}, got {raw!r}") from None
    return f.check(raw, flag)


def add_command_options(
    parser, fields: Iterable[Field], required: Iterable[str] = (), parse: dict[str, Callable[[str], Any]] | None = None
) -> None:
    """A command's own options, each from its declaration: a bool is a switch (off unless given), the
    others take a value with the declared default (check them with :func:`check_command_options`).
    ``parser`` may be a group (``add_mutually_exclusive_group()``: one of the fields at most);
    ``required``: the names of fields that must be given; ``parse``: by name, how a value's text is
    read where a plain number is not enough (a percentage), raising ValueError on text it cannot read."""
    required, parse = set(required), parse or {}
    for f in fields:
        flags = option_flags(f)
        need = f.name in required
        help = f.doc if need else _command_help(f)
        kw: dict[str, Any] = dict(dest=f.name, default=f.default, help=_help(help))
        if need:
            kw["required"] = True
        if f.kind == "bool":  # a switch; one that is on by default also has its --no- spelling
            parser.add_argument(*flags, action=argparse.BooleanOptionalAction if f.default else "store_true", **kw)
        elif f.kind == "choice":
            parser.add_argument(*flags, choices=f.choices, **kw)
        else:
            meta = _METAVAR.get(f.kind) if f.kind in VECTOR_SIZES else None
            if meta is None:
                meta = f.unit.upper() if f.unit and " " not in f.unit else _METAVAR.get(f.kind, f.name.upper())
            parser.add_argument(*flags, type=_reader(f, parse.get(f.name)), metavar=meta, **kw)


def _reader(f: Field, parse: Callable[[str], Any] | None) -> Callable[[str], Any]:
    """The argparse type of a field's value: its text read as the kind (an integer may be written 1e5);
    text that is no such value: `expected <what>, got <text>` (argparse names the option)."""
    if parse is None and f.kind not in ("int", "float", *VECTOR_SIZES):
        return str

    def read(text: str) -> Any:
        try:
            if parse is not None:
                return parse(text)
            if f.kind in VECTOR_SIZES:  # R,G,B (or one number for all)
                return tuple(float(x) for x in text.split(","))
            if f.kind == "float":
                return float(text)
            try:
                return int(text)
            except ValueError:
                x = float(text)  # 1e5: an integer in a float's spelling
                if not (math.isfinite(x) and x == int(x)):
                    raise
                return int(x)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected {f.expected()}, got {text!r}") from None

    read.__name__ = f.kind  # argparse's name for the type
    return read


def own_default(f: Field, default: Any, why: str, shown: str = "") -> Field:
    """A declared setting as a command's own option whose default differs on purpose: the help says
    so (``why``: "this benchmark's own default, smaller than a render's 2048 so that ..."; ``shown``:
    the default in words, where it is computed)."""
    return dataclasses.replace(f, default=default, doc=f"{f.doc}: {why}", none="", flags=(), shown=shown)


def _command_help(f: Field) -> str:
    if f.kind == "bool":
        return f"{f.doc} (default: {f.default})" if f.default else f.doc
    values = f"; {f.expected(with_none=False)}" if f.kind in ("int", "float", *VECTOR_SIZES) and f.range else ""
    if f.default is None:
        return f"{f.doc}{values} (default: {f.shown or f.none or 'none'})"
    unit = f" {f.unit}" if f.unit else ""
    return f"{f.doc}{values} (default: {f.shown or f'{f.default}{unit}'})"


def check_command_options(args, fields: Iterable[Field]) -> None:
    """Every declared option of a command given a value outside its declaration: an error naming it;
    the values checked are left on ``args`` in their canonical form (a vector's one number repeated)."""
    for f in fields:
        value = getattr(args, f.name, None)
        if value is not None and f.kind in ("int", "float", *VECTOR_SIZES):
            setattr(args, f.name, f.check(value, option_flags(f)[0]))  # canonical: one number fills R,G,B
