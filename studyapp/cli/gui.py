"""``studyapp gui``: the experimenter console (also what ``studyapp`` alone runs).

    studyapp gui [--protocol FILE] [--participant ID] [--results DIR] [--resume]
                 [--simulated-participant] [--start] [--seed N] [--audio SPEC] [--midi SPEC]
                 [--experimenter NAME] [--session-number N] [--notes TEXT] [--order-row N]
                 [--participant-window] [--participant-screen N] [--participant-screenshot FILE]
                 [--screenshot FILE] [--size WxH] [--measure-scope SECONDS]

``--screenshot FILE`` starts the console, lets it run, saves it as a PNG and
exits; ``--size WxH`` sizes the console's window (e.g. 1366x768, a lab
laptop's screen), so a screenshot shows it at that size; ``--measure-scope
SECONDS`` prints the live scope's frame rate with every trace on and exits.
``--participant-screen N`` opens the participant's
window full-screen on screen N (from 0), remembered for the next
``--participant-window``; ``--participant-screenshot FILE`` saves that window
as a PNG (with ``--start``, once the first trial shows) and exits. The
session-info options fill the set-up panel's fields (checked as ``studyapp run``
checks them). See docs/gui.md.
"""

import re

from studyapp.cli import number_options
from studyapp.cli.device_choice import add_device_option
from studyapp.cli.session_info_options import add_session_info_options

SIZES = ((800, 600), (7680, 4320))  # px: the smallest and largest window --size allows


def parse_size(text):
    """``"1366x768"`` -> ``(1366, 768)``; ``UserError`` naming the value and what is allowed."""
    from studyapp.errors import UserError

    (w_min, h_min), (w_max, h_max) = SIZES
    match = re.fullmatch(r"\s*(\d+)\s*[xX×]\s*(\d+)\s*", text or "")
    if match is None or not (w_min <= int(match[1]) <= w_max and h_min <= int(match[2]) <= h_max):
        raise UserError(f"--size {text}: allowed is WIDTHxHEIGHT in pixels, from {w_min}x{h_min} to {w_max}x{h_max}")
    return int(match[1]), int(match[2])


def register(sub):
    parser = sub.add_parser("gui", help="the experimenter console (the default command)")
    parser.add_argument("--protocol", metavar="FILE",
                        help="study protocol (default: protocols/sinclair2014.toml, else the first in protocols/)")
    parser.add_argument("--participant", metavar="ID", help="participant pseudonym to fill in")
    parser.add_argument("--results", default=None, metavar="DIR",
                        help="results folder (default: the one last used in the console, else $STUDYAPP_RESULTS, "
                             "else ~/.local/share/studyapp/results; made absolute)")
    parser.add_argument("--resume", action="store_true", help="tick 'resume the unfinished session'")
    parser.add_argument("--simulated-participant", action="store_true", help="a simulated participant plays")
    parser.add_argument("--start", action="store_true", help="start the session at once (needs --participant)")
    parser.add_argument("--seed", type=number_options.seed, default=None, metavar="N", help="session seed (with --start)")
    parser.add_argument("--audio", default="device", metavar="SPEC",
                        help="device | device:NAME | wav:FILE | null (default: device, or no sound if none is found)")
    parser.add_argument("--midi", default="first", metavar="SPEC",
                        help="PORT | first | virtual | none (default: first, or the on-screen knobs if none is found)")
    parser.add_argument("--participant-window", action="store_true", help="open the participant's window too")
    parser.add_argument("--participant-screen", type=int, metavar="N",
                        help="the participant's window full-screen on screen N (from 0; remembered on this machine)")
    parser.add_argument("--participant-screenshot", metavar="FILE",
                        help="save the participant's window as a PNG and exit")
    parser.add_argument("--screenshot", metavar="FILE", help="save the running console as a PNG and exit")
    parser.add_argument("--size", metavar="WxH",
                        help="window size in pixels, e.g. 1366x768 (800x600 to 7680x4320)")
    parser.add_argument("--measure-scope", type=float, metavar="SECONDS",
                        help="measure the scope's frame rate with every trace on for SECONDS, print it and exit")
    add_device_option(parser)
    add_session_info_options(parser)
    parser.set_defaults(func=run)


def run(args):
    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.gui.display import require_display

    from studyapp.experiment.session_info import check_experimenter, check_notes, check_session_number

    check_experimenter(args.experimenter)
    check_session_number(args.session_number)
    check_notes(args.notes)
    protocol = None
    if args.protocol:  # a bad protocol (a FIFO, a device, a bad field) is one line before any window opens
        from studyapp.experiment.protocol import load_protocol

        protocol = load_protocol(args.protocol)
    output_paths.check_audio(args.audio, inputs=[args.protocol] if args.protocol else [])
    if args.results is not None and not args.results.strip():  # Path("") would be the working folder
        raise UserError("--results '': empty: allowed is a results folder")
    _check_before_the_console(args, protocol)
    require_display()
    if args.device is not None:
        from studyapp.cli.device_choice import check_device, link_options
        from studyapp.experiment.protocol import load_protocol
        from studyapp.gui.app import default_protocol

        protocol = args.protocol or default_protocol()
        loaded = load_protocol(protocol) if protocol else None
        link = check_device(args.device, loaded.rate if loaded else 5000.0, loaded)
        args.link_options = link_options(args, link)
    elif args.device_latency is not None or args.device_silence is not None:
        from studyapp.cli.device_choice import link_options
        from studyapp.gui.device_panel import remembered

        args.link_options = link_options(args, remembered())
    if args.start and not args.participant:
        raise UserError("--start: allowed only with --participant ID")
    if args.measure_scope is not None and not 0.5 <= args.measure_scope <= 600:
        raise UserError(f"--measure-scope {args.measure_scope:g}: allowed is 0.5 to 600 seconds")
    for option in ("screenshot", "participant_screenshot"):
        path = getattr(args, option)
        if path and not path.lower().endswith(".png"):
            raise UserError(f"--{option.replace('_', '-')} {path}: allowed is a file name ending in .png")
        if path:
            output_paths.check_file(path, f"--{option.replace('_', '-')}")
    if args.size is not None:
        args.size = parse_size(args.size)
    try:
        from studyapp.gui.app import main
    except ImportError as exc:
        raise UserError(f"the GUI cannot start: {exc} (install PySide6-Essentials and pyqtgraph)") from None
    return main(args)


def _check_before_the_console(args, protocol):
    """``--results``, ``--audio`` and ``--order-row`` checked before any window opens (issue 33, item 6: the
    console opened instead, and with ``--screenshot`` never exited)."""
    from pathlib import Path

    from studyapp.engine.audio.sinks import parse as parse_audio
    from studyapp.errors import UserError
    from studyapp.experiment.session_info import check_order_row

    results = Path(args.results) if args.results is not None else None
    if results is not None and results.exists() and not results.is_dir():
        raise UserError(f"--results {args.results}: not a folder: allowed is a results folder (made if missing)")
    parse_audio(args.audio)
    if args.order_row is None:
        return
    if protocol is not None:
        check_order_row(protocol, args.order_row)
    elif not str(args.order_row).strip().isdigit():
        raise UserError(f"--order-row {args.order_row}: allowed is a whole number from 0 "
                        "(below the protocol's number of orders)")
