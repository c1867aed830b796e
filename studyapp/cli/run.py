"""``studyapp run --protocol FILE --participant ID [--simulated-participant] [--headless]
[--resume] [--results DIR] [--seed N] [--audio SPEC] [--midi SPEC] [--participant-screen N]
[--replay-gesture EVENTS] [--device simulated|PATH_OR_URL] [--experimenter NAME] [--session-number N]
[--notes TEXT] [--order-row N]``: run one participant's session.

``--device`` (the console only): the device the participant holds (cli/device_choice.py). With ``--headless``
only ``simulated`` is allowed: a headless session steps the simulated device as fast as it can, and a device on a
link runs on its own clock (``--help`` says so). On a device on a
link, a session with an adjustment task is first checked by the model (live/rig_check.py): when the link's
latency makes LVT's predicted breakdown fall below 1.5x the best estimator's, a ``studyapp run: warning: ...``
line says so, and the console asks again at Start.

The experimenter's fields and the order row are stored in session.json
(``experiment.session_info`` says what is allowed); the order row in force is
printed with the session folder's line.

With ``--simulated-participant --headless`` the session runs in this process
without a display: the closed loop is stepped directly and the simulated
participant plays every trial (the demo, the end-to-end check, an in-silico
pilot). Progress goes to stderr; the session folder is printed on stdout.
``--audio wav`` archives what would have been heard, through the live
engine's signal chain, as ``audio.wav`` and ``audio_cues.csv`` in the session
folder, as a live session does (``session.headless_audio``); ``null`` (the
default headless) renders no audio.
Without ``--headless`` the session runs in the experimenter console
(``studyapp.gui.run_session(args)``), with ``--audio``, ``--midi`` and
``--participant-screen`` as ``studyapp gui`` takes them; the participant's
window opens full-screen on the chosen screen, or on the screen this machine
remembers (a resumed session after a crash gets its participant screen back).

``--replay-gesture EVENTS`` (a session's events.jsonl, or its folder): the
simulated participant's hand moves as that session's participant bowed
(its ``hand_trace`` records, experiment/hand_trace.py), trial by trial.
"""

from studyapp.cli import number_options
from studyapp.cli.device_choice import HEADLESS_WHY, SIMULATED, add_device_option
from studyapp.cli.session_info_options import add_session_info_options, session_info_of


def register(sub):
    parser = sub.add_parser("run", help="run a participant's session of a study protocol")
    parser.add_argument("--protocol", required=True, metavar="FILE", help="study protocol (TOML), e.g. protocols/demo.toml")
    parser.add_argument("--participant", required=True, metavar="ID",
                        help="participant pseudonym: 1 to 32 letters, digits, '_' or '-'")
    parser.add_argument("--simulated-participant", action="store_true",
                        help="a simulated participant plays the session")
    parser.add_argument("--headless", action="store_true",
                        help="no display: run in this process (needs --simulated-participant)")
    parser.add_argument("--resume", action="store_true", help="continue the participant's unfinished session")
    parser.add_argument("--results", default=None, metavar="DIR",
                        help="results folder (default: $STUDYAPP_RESULTS, else ~/.local/share/studyapp/results; made absolute)")
    parser.add_argument("--seed", type=number_options.seed, default=None, metavar="N",
                        help="session seed (default: from the study seed and the participant's enrolment)")
    parser.add_argument("--audio", default=None, metavar="SPEC",
                        help="headless: wav (audio.wav and audio_cues.csv in the session folder) or null (default); "
                             "in the console: device | device:NAME | wav:FILE | null, as for gui")
    parser.add_argument("--midi", default=None, metavar="SPEC",
                        help="the console's MIDI input: PORT | first | virtual | none (default: first)")
    parser.add_argument("--participant-screen", type=int, metavar="N",
                        help="the participant's window full-screen on screen N (from 0; remembered on this machine)")
    parser.add_argument("--replay-gesture", metavar="EVENTS",
                        help="the simulated participant bows as logged in EVENTS (a session's events.jsonl "
                             "or folder; needs --simulated-participant)")
    add_device_option(parser, headless=True)
    add_session_info_options(parser)
    parser.set_defaults(func=run)


def replay_traces(path):
    """{step: hand_trace record} from ``path`` (a session's events.jsonl, or its folder); ``UserError`` if none."""
    from pathlib import Path

    from studyapp.errors import UserError
    from studyapp.experiment.hand_trace import load_traces
    from studyapp.experiment.session_log import read_events

    path = Path(path)
    events = path / "events.jsonl" if path.is_dir() else path
    if not events.is_file():
        raise UserError(f"--replay-gesture {path}: not found: allowed is a session's events.jsonl or its folder")
    return load_traces(read_events(events), f"--replay-gesture {events}")


def run(args):
    import contextlib
    import sys
    from pathlib import Path

    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.experiment.protocol import load_protocol
    from studyapp.experiment.session import check_participant
    from studyapp.experiment.session_info import check_experimenter, check_notes, check_order_row, check_session_number

    check_participant(args.participant)
    check_experimenter(args.experimenter)
    check_session_number(args.session_number)
    check_notes(args.notes)
    if args.seed is not None and not 0 <= args.seed < 2**63:
        raise UserError(f"--seed {args.seed}: allowed is an integer from 0 to 2**63 - 1")
    if args.headless and not args.simulated_participant:
        raise UserError("--headless: allowed only with --simulated-participant (a person takes part through the GUI)")
    if args.headless and args.audio not in (None, "wav", "null"):
        raise UserError(f"--audio {args.audio}: allowed headless is wav (audio.wav in the session folder) or null")
    if args.headless:
        if args.device not in (None, SIMULATED):
            raise UserError(f"--device {args.device}: allowed with --headless is only simulated: {HEADLESS_WHY}; "
                            "run it without --headless (the console)")
        for option in ("midi", "participant_screen", "device_latency", "device_silence"):
            if getattr(args, option) is not None:
                raise UserError(f"--{option.replace('_', '-')}: allowed only without --headless (the console's)")
    if args.replay_gesture is not None and not args.simulated_participant:
        raise UserError("--replay-gesture: allowed only with --simulated-participant (it moves the simulated hand)")
    args.replay = replay_traces(args.replay_gesture) if args.replay_gesture is not None else None
    protocol = load_protocol(args.protocol)
    check_order_row(protocol, args.order_row)
    from studyapp.experiment.results_folder import absolute, used_rows_text

    if args.results is not None and not args.results.strip():  # "" would be the working folder
        raise UserError("--results '': empty: allowed is a results folder")
    args.results = str(absolute(args.results))  # one study, one folder: never relative to where it was started
    output_paths.check_folder(args.results, "--results")
    used = used_rows_text(Path(args.results) / protocol.study, args.simulated_participant)  # before this one enrols
    if args.resume:
        from studyapp.experiment.enrolment import check_same_player
        from studyapp.experiment.session import lock_taken

        if not lock_taken(Path(args.results) / protocol.study / args.participant):  # the holder's refusal first
            check_same_player(args.results, protocol.study, args.participant, args.simulated_participant)
    if not args.headless:
        from studyapp.cli.device_choice import link_options, probe_device, rig_check_line

        output_paths.check_audio(args.audio, inputs=[args.protocol, *filter(None, [args.replay_gesture])])
        args.audio = args.audio or "device"
        args.midi = args.midi or "first"
        link, loop = probe_device(args.device, protocol.rate, protocol)
        args.link_options = link_options(args, link)
        if not args.resume:
            args.rig_prediction = rig_check_line(protocol, link, lambda text: print(f"studyapp run: {text}",
                                                                                   file=sys.stderr, flush=True),
                                                 loop, args.link_options.get("device_latency"))
        return _run_in_gui(args)

    from studyapp.experiment.hand_trace import ReplayingHand
    from studyapp.experiment.session import Session
    from studyapp.experiment.session_log import LogWriteError
    from studyapp.experiment.session_runner import SessionRunner
    from studyapp.experiment.session_info import order_text
    from studyapp.experiment.simulated_participant import SimulatedParticipant
    from studyapp.live.headless_audio import ArchivingRunner

    def progress(message):
        print(f"studyapp run: {message}", file=sys.stderr, flush=True)

    archive = args.audio == "wav"
    if args.resume:
        session = Session.resume(protocol, args.participant, args.results, seed=args.seed, **session_info_of(args))
    else:
        session = Session.create(protocol, args.participant, args.results, seed=args.seed,
                                 apparatus={"device": "simulated", "participant": "simulated",
                                            "audio": "archived (headless)" if archive else False},
                                 **session_info_of(args))
    for note in session.notes:
        progress(f"warning: {note}")
    progress(f"results folder {args.results}; before this session, {used}")
    progress(f"session {session.folder} ({len(session.finished_steps())} of {len(session.schedule)} trials done, "
             f"{order_text(session.info)})")
    runner = (ArchivingRunner(session, progress=progress) if archive
              else SessionRunner(session, progress=progress, simulated=True))
    if archive:
        progress(f"audio: archiving what is heard to {runner.path}")
    try:
        runner.begin()
        player = runner if args.replay is None else ReplayingHand(runner, args.replay)
        SimulatedParticipant(session.seed).play(player)
        complete = runner.finish()
    except BaseException as exc:
        if not isinstance(exc, LogWriteError):
            # a log that cannot be written cannot take the note either: the message says why
            with contextlib.suppress(LogWriteError):
                runner.finish("interrupted")
        if archive:
            runner.close()  # the audio up to here stays readable
        session.close()
        raise
    session.close()
    progress(f"session {'complete' if complete else 'stopped'}: {session.folder}")
    print(session.folder)
    return 0


def _run_in_gui(args):
    from studyapp import gui

    return gui.run_session(args)
