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
