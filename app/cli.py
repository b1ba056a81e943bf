"""`skinlab` command line: subcommands live in app/commands/ (one module each)."""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from app.commands import COMMAND_MODULES


class UserError(Exception):
    """A problem with the user's input: printed as one clear line, exit status 2."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="skinlab", description="Realtime subsurface-scattering workbench")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMAND_MODULES:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:
                continue  # command not written yet
            raise
        mod.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
    args = build_parser().parse_args(argv)
    from app.gl.context import ContextError
    from app.gl.shader_source import ShaderError

    try:
        return int(args.func(args) or 0)
    except (UserError, ContextError, ShaderError, ValueError, FileNotFoundError) as exc:
        if os.environ.get("SKINLAB_DEBUG"):
            raise  # SKINLAB_DEBUG=1 shows the traceback behind the one-line message
        print(f"skinlab {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
