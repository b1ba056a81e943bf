"""CLI subcommands. Each module defines ``register(subparsers)`` which adds its parser and sets
``func`` (called with the parsed args, returns an exit code). `skinlab.cli` imports the modules listed
in ``COMMAND_MODULES``."""

COMMAND_MODULES = [
    "skinlab.commands.render",
    "skinlab.commands.demo",
    "skinlab.commands.bench",
    "skinlab.commands.profile",
    "skinlab.commands.mc",
    "skinlab.commands.view",
    "skinlab.commands.reference",
    "skinlab.commands.scenes",
    "skinlab.commands.compare",
    "skinlab.commands.export",
]


def refused_option(message: str):
    """An argparse action for an option name that is refused with `message` (a name with two
    meanings across commands, say: ``--albedo``), as a usage error: one line, exit status 2."""
    import argparse

    class Refused(argparse.Action):
        def __init__(self, option_strings, dest, **kwargs):
            super().__init__(option_strings, argparse.SUPPRESS, default=argparse.SUPPRESS, **kwargs)

        def __call__(self, parser, namespace, values, option_string=None):
            parser.error(f"{option_string}: {message}")

    return Refused
