"""The GUI application: Qt set-up, the console, and what the command line asked for.

``main(args)`` builds the ``QApplication`` (or reuses one, e.g. under
pytest-qt), the ``SessionController`` (audio and MIDI as asked, falling back
to no sound and the on-screen knobs when nothing is found), and the console;
loads the protocol (``--protocol``, else ``protocols/sinclair2014.toml`` or the
first protocol in ``protocols/``); fills in the participant; starts the
session at once with ``--start``; sizes the window (``--size``, already
parsed into pixels); and runs the event loop. ``--screenshot``,
``--participant-screenshot`` and ``--measure-scope`` run the console
unattended and exit. The participant's window opens with
``--participant-window``, ``--participant-screen N`` or
``--participant-screenshot``, full-screen on the chosen (or remembered)
screen; a screen that does not exist is refused before anything starts.
"""

import signal
from pathlib import Path

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication

from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.results_folder import absolute
from studyapp.experiment.session_info import check_order_row
from studyapp.gui.setup_panel import find_protocols

DEFAULT_PROTOCOL = "protocols/sinclair2014.toml"


def application():
    """The process's ``QApplication`` (made once)."""
    app = QApplication.instance()
    if app is None:
        app = QApplication(["studyapp"])
        app.setApplicationName("studyapp")
    return app


def default_protocol():
    if Path(DEFAULT_PROTOCOL).is_file():
        return DEFAULT_PROTOCOL
    found = find_protocols()
    return found[0] if found else None


def build(args):
    """The controller and console for ``args`` (not yet shown); ``UserError`` for bad arguments."""
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    protocol = getattr(args, "protocol", None) or default_protocol()
    if protocol is not None and getattr(args, "order_row", None) is not None:
        check_order_row(load_protocol(protocol), args.order_row)  # refused before any engine starts
    application()
    device = _device(getattr(args, "device", None))
    controller = SessionController(audio=getattr(args, "audio", "device"), midi=getattr(args, "midi", "first"),
                                   device=device)
    controller.apparatus.device_options = dict(getattr(args, "link_options", None) or {})  # --device-latency, ...
    console = Console(controller)
    console.device_panel.show_choice(device)
    kept = getattr(args, "rig_prediction", None)  # studyapp run predicted it already
    if kept is not None:
        console.rig_prediction.cache.put(kept[0], kept[1])
    protocol = getattr(args, "protocol", None) or default_protocol()
    if protocol is not None:
        controller.load_protocol(protocol)
        console.setup.select_protocol(protocol)
    if getattr(args, "participant", None):
        console.setup.participant.setText(args.participant)
    if getattr(args, "results", None) is not None:  # else the folder this machine remembers (setup_panel.py)
        console.setup.results.setText(str(absolute(args.results)))
    console.setup.resume.setChecked(bool(getattr(args, "resume", False)))
    console.setup.simulated.setChecked(bool(getattr(args, "simulated_participant", False)))
    console.replay = getattr(args, "replay", None)
    console.setup.fill_session_info(**{key: getattr(args, key, None)
                                       for key in ("experimenter", "session_number", "notes", "order_row")})
    return controller, console


def _device(given):
    """The device to run on: ``--device`` (simulated or a link), else the one remembered on this machine."""
    from studyapp.gui.device_panel import remembered

    if given is not None:
        return None if given == "simulated" else given
    return remembered()


def main(args):
    """Run the console until it is closed; returns the exit code."""
    from studyapp.gui.participant_placement import place
    from studyapp.gui.participant_screen import choose_screen

    app = application()
    screen_choice = getattr(args, "participant_screen", None)
    shot = getattr(args, "participant_screenshot", None)
    participant = getattr(args, "participant_window", False) or screen_choice is not None or bool(shot)
    screen = choose_screen(screen_choice) if participant else None
    controller, console = build(args)
    # Ctrl-C in the terminal, and SIGTERM (a logout, a service manager, ``kill``), close the console cleanly:
    # the session aborted and logged, the engine stopped, its shared memory unlinked. Installed before any
    # engine starts (SIGTERM's default left 3 segments and 3 semaphores to the resource tracker); the close
    # is queued, so it runs inside the event loop even when the signal comes before it (Python sees signals
    # between Qt events)
    for number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(number, lambda *_: QTimer.singleShot(0, console.shut_down))
    size = getattr(args, "size", None)
    if size is not None:
        console.set_size(*size)
    console.show()
    if screen is not None:
        place(console, screen)  # never over the console's session buttons (participant_placement.py)
    if participant:
        console.show_participant.setChecked(True)
    if shot:
        from studyapp.gui.participant_screenshot import ParticipantScreenshot

        console.unattended = ParticipantScreenshot(console, shot, wait_for_trial=getattr(args, "start", False))
    elif getattr(args, "screenshot", None):
        from studyapp.gui.screenshot import Screenshot

        console.unattended = Screenshot(console, args.screenshot)
    elif getattr(args, "measure_scope", None):
        from studyapp.gui.scope_benchmark import ScopeBenchmark

        console.unattended = ScopeBenchmark(console, args.measure_scope)
    if getattr(args, "start", False) and not (getattr(args, "screenshot", None) or getattr(args, "measure_scope", None)):
        _start_when_possible(console, getattr(args, "seed", None))
    code = app.exec()
    console.shut_down()  # an unattended run may leave a session running: no one to ask
    return code


def _start_when_possible(console, seed):
    if console.start_session(seed=seed) is None:
        raise UserError(console.setup.error.text())
