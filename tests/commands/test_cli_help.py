"""Every option says what it is; every option with a default states it (help texts are the manual)."""

import argparse

from skinlab.cli import build_parser


def _subparsers(parser, prefix=()):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*prefix, name), sub
                yield from _subparsers(sub, (*prefix, name))


def _forms(value) -> set[str]:
    """How a default may be written: 2048, 0.05, 1e5 for 100000.0, out/render.png."""
    if isinstance(value, float):
        mantissa, exp = f"{value:e}".split("e")
        return {f"{value:g}", f"{float(mantissa):g}e{int(exp)}", repr(value)}
    return {str(value)}


def test_every_option_has_help_and_states_its_default():
    missing = []
    for path, sub in _subparsers(build_parser()):
        for a in sub._actions:
            if isinstance(a, argparse._HelpAction | argparse._SubParsersAction) or a.help == argparse.SUPPRESS:
                continue
            name = " ".join(path) + " " + (a.option_strings[-1] if a.option_strings else a.dest)
            if not a.help:
                missing.append(f"{name}: no help")
                continue
            if (
                a.option_strings
                and a.default not in (None, False)
                and not isinstance(a, argparse._StoreTrueAction | argparse._StoreFalseAction)
            ):
                if "default" not in a.help or not any(form in a.help for form in _forms(a.default)):
                    missing.append(f"{name}: default {a.default!r} not stated in {a.help!r}")
    assert not missing, "\n".join(missing)


def test_accuracy_help_defaults_come_from_the_sweeps():
    from skinlab.bench.accuracy import SWEEPS

    bench = dict(_subparsers(build_parser()))[("bench", "accuracy")]
    helps = {a.dest: a.help for a in bench._actions}
    from skinlab.bench.sweep import base_setting

    size = {n: base_setting("exact", SWEEPS[n]).value("size") for n in ("full", "quick")}
    assert f"default: {size['full']}; --quick {size['quick']}" in helps["exact_size"]
    assert f"default: {SWEEPS['full'].photons}; --quick {SWEEPS['quick'].photons}" in helps["photons"]


def test_a_named_command_imports_only_its_own_module():
    """`skinlab render ...` builds the parser of `render` alone: no other command's module (and what
    it imports) is loaded; its --help reads as in the full parser; an unknown name gets the full list."""
    import subprocess
    import sys

    code = (
        "import sys; from skinlab.cli import build_parser; build_parser('scenes'); "
        "print(sorted(m for m in sys.modules if m.startswith('skinlab.commands.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    from skinlab.commands import COMMAND_MODULES

    loaded = set(eval(out))
    assert loaded & set(COMMAND_MODULES) == {"skinlab.commands.scenes"}, out  # no other command's module
    assert loaded - set(COMMAND_MODULES) <= {"skinlab.commands.field_options"}, out  # options from declarations
    one = dict(_subparsers(build_parser("render")))[("render",)].format_help()
    assert one == dict(_subparsers(build_parser()))[("render",)].format_help()
    assert len(dict(_subparsers(build_parser("no-such-command")))) > 5
