"""The ``studyapp`` command line.

Each sub-command lives in its own module of this package with two functions:
``register(subparsers)`` adds its parser (argparse only, so start-up stays fast)
and sets ``func``; the function imports what it needs and returns an exit code.
A ``UserError`` becomes one line on stderr and exit code 2; so does a
malformed command line (argparse's own usage dump is several lines), a
number option that is not finite, a negative ``--seed`` (``number_options``),
and a file that cannot be written (an ``OSError``: a full disk, a read-only
folder), which names the file. An ``EngineError`` (the real-time engine
failed, not the user) is one line and exit code 1. One line even when the
path or value named holds a newline: it is shown escaped (``one_line``).
"""

import argparse
import importlib
import sys

from studyapp import __version__
from studyapp.cli import number_options
from studyapp.errors import EngineError, UserError

# Module names under studyapp.cli, in the order shown by --help. A module that
# does not exist yet is skipped, so layers can land one at a time.
COMMANDS = [
    "gui",
    "demo",
    "estimators",
    "estimate",
    "simulate",
    "simulate_set",
    "breakdown",
    "optimise",
    "evaluate",
    "tradeoff",
    "live",
    "run",
    "plan",
    "notes",
    "export",
    "analyse",
    "bench",
]


class UsageError(UserError):
    """The command line itself is malformed (unknown option, a value of the wrong type)."""


class Parser(argparse.ArgumentParser):
    """argparse with errors raised, not printed with the usage: ``main`` prints them as one line."""

    def error(self, message):
        raise UsageError(f"{message} (see '{self.prog} --help')")


def build_parser():
    parser = Parser(
        prog="studyapp",
        description="Velocity estimation studies for audio-haptic stick-slip simulation.",
    )
    parser.add_argument("--version", action="version", version=f"studyapp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"studyapp.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"studyapp.cli.{name}":
                continue
            raise
        module.register(sub)
    number_options.checked(parser)
    return parser


def main(argv=None):
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            if "gui" in parser._subparsers._group_actions[0].choices:
                args = parser.parse_args(["gui"])
            else:
                parser.print_help()
                return 0
        return args.func(args) or 0
    except UserError as exc:
        print(f"studyapp: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except EngineError as exc:
        print(f"studyapp: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("studyapp: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader (e.g. `| head`) has gone: stop quietly, as Unix tools do
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:
        # the outputs are atomic (studyapp.io.atomic): a failed write leaves no partial file to mention
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"studyapp: error: {one_line(f'{where}{exc.strerror or exc}')}: nothing written", file=sys.stderr)
        return 2


def one_line(message):
    """``message`` on one line: a path or value holding a newline is shown with it escaped, as repr() does."""
    return str(message).replace("\r", "\\r").replace("\n", "\\n")
