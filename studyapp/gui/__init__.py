"""The experimenter's GUI (PySide6 + pyqtgraph): the only layer that imports Qt.

``run_session(args)`` is what ``studyapp run`` calls without ``--headless``:
the console with the session started at once, and the participant's window
open: full-screen on ``--participant-screen N``, else on the screen this
machine remembers (so ``run --resume`` after a crash gives the participant
their screen back), else as an ordinary window.
"""


def run_session(args):
    from studyapp.gui.display import require_display

    require_display()
    from studyapp.gui.app import main

    args.start = True
    args.participant_window = True  # a participant takes part: their window opens with the session
    return main(args)
