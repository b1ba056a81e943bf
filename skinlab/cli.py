"""`skinlab` command line: subcommands live in skinlab/commands/ (one module each).

Bad input ends in one line on stderr naming the file or option and what was expected, exit status
2, never a traceback (``SKINLAB_DEBUG=1`` shows it). Output piped into a reader that stops early
(``skinlab mc --json | head``) ends quietly with status 141, as a shell tool killed by SIGPIPE."""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings

from skinlab.commands import COMMAND_MODULES

EXIT_BAD_INPUT = 2
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a shell reports for `cmd | head`
EXIT_INTERRUPTED = 130  # 128 + SIGINT


class UserError(Exception):
    """A problem with the user's input: printed as one clear line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    """Usage mistakes (an unknown choice, a missing argument) as one line, not the usage block."""

    def error(self, message: str):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def version() -> str:
    """The installed package's version (its metadata), e.g. ``skinlab 0.2.0``."""
    import skinlab

    return f"skinlab {skinlab.__version__}"


class _VersionAction(argparse.Action):
    """--version without building the rest of the parser first (it imports every command)."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version())
        parser.exit()


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser; with ``command`` (a subcommand's name) only that subcommand's module
    is imported and registered (what `main` does when the command line names one: a command does not
    pay for importing every other)."""
    parser = OneLineParser(prog="skinlab", description="Realtime subsurface-scattering workbench")
    parser.add_argument("--version", action=_VersionAction, help="print the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    only = f"skinlab.commands.{command}"
    for name in [only] if only in COMMAND_MODULES else COMMAND_MODULES:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:
                continue  # command not written yet
            raise
        mod.register(sub)
    return parser


def _os_error_line(exc: OSError) -> str:
    """'PATH: reason' for a file-system error (a folder where a file should be, no permission...)."""
    reason = exc.strerror or str(exc)
    if exc.filename is not None:
        return f"{exc.filename}: {reason}"
    return reason


def _quiet_broken_pipe() -> int:
    # the reader has gone: point stdout at /dev/null so the interpreter's final flush cannot fail again
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except OSError:
        pass
    return EXIT_BROKEN_PIPE


def main(argv: list[str] | None = None) -> int:
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
    if (sys.argv[1:] if argv is None else argv) == ["--version"]:  # answers before any command module loads
        print(version())
        return 0
    words = sys.argv[1:] if argv is None else argv
    args = build_parser(words[0] if words and not words[0].startswith("-") else None).parse_args(argv)
    with warnings.catch_warnings():  # restored when main returns (tests call it in-process)
        if not os.environ.get("SKINLAB_DEBUG"):
            # numpy's float warnings ("overflow encountered in multiply") are noise around a one-line
            # error or a result: what matters is checked and said in words (SKINLAB_DEBUG=1 shows them)
            warnings.filterwarnings("ignore", category=RuntimeWarning)
        return _run(args)


def _run(args) -> int:
    from skinlab.gl.context import ContextError
    from skinlab.gl.shader_source import ShaderError

    try:
        code = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at interpreter exit
        return code
    except BrokenPipeError:
        return _quiet_broken_pipe()
    except KeyboardInterrupt:  # Ctrl-C: files are written to a temporary name first, so nothing is half-written
        print(f"skinlab {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (UserError, ContextError, ShaderError, ValueError, FileNotFoundError, OSError) as exc:
        if os.environ.get("SKINLAB_DEBUG"):
            raise  # SKINLAB_DEBUG=1 shows the traceback behind the one-line message
        line = _os_error_line(exc) if isinstance(exc, OSError) and exc.filename is not None else str(exc)
        if not isinstance(exc, ShaderError):  # shader errors quote source lines; the rest is one line
            line = " ".join(line.split("\n"))
        print(f"skinlab {args.command}: error: {line}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
