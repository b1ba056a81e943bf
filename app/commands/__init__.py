"""CLI subcommands. Each module defines ``register(subparsers)`` which adds its parser and sets
``func`` (called with the parsed args, returns an exit code). `app.cli` imports the modules listed
in ``COMMAND_MODULES``."""

COMMAND_MODULES = [
    "app.commands.render",
    "app.commands.demo",
    "app.commands.bench",
    "app.commands.profile",
    "app.commands.mc",
    "app.commands.view",
    "app.commands.reference",
]
