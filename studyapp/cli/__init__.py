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
import os
import sys

from studyapp import __version__
from studyapp.cli import (
    analyse, bench, breakdown, compile_kernels, demo, device_emulator, estimate, estimators, evaluate, export, firmware_params, gui, live,
    notes, optimise, plan, run,
    simulate, simulate_set, tradeoff,
)
from studyapp.cli.number_options import finite_float, integer
from studyapp.errors import EngineError, UserError

# the sub-commands' modules, in the order shown by --help
COMMANDS = [gui, demo, estimators, estimate, simulate, simulate_set, breakdown, optimise, evaluate, tradeoff, live, run,
            plan, notes, export, analyse, bench, compile_kernels, device_emulator, firmware_params]


class UsageError(UserError):
    """The command line itself is malformed (unknown option, a value of the wrong type)."""


class Parser(argparse.ArgumentParser):
    """argparse with errors raised, not printed with the usage: ``main`` prints them as one line.

    Every option of ``type=float`` or ``type=int``, in this parser, its groups and its
    sub-commands' parsers (argparse makes those of this class too), is read by
    ``number_options`` (finite floats, no digit grouping): argparse looks a type up in
    the parser's registry before calling it.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("type", float, finite_float)
        self.register("type", int, integer)

    def error(self, message):
        raise UsageError(f"{message} (see '{self.prog} --help')")


def build_parser():
    parser = Parser(
        prog="studyapp",
        description="Velocity estimation studies for audio-haptic stick-slip simulation.",
    )
    parser.add_argument("--version", action="version", version=f"studyapp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module in COMMANDS:
        module.register(sub)
    return parser


def main(argv=None):
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command is None:
            args = parser.parse_args(["gui"])
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
