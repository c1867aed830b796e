"""The experimenter's GUI (PySide6 + pyqtgraph): the only layer that imports Qt.

``run_session(args)`` is what ``studyapp run`` calls without ``--headless``:
the console with the session started at once.
"""


def run_session(args):
    from studyapp.gui.display import require_display

    require_display()
    from studyapp.gui.app import main

    args.start = True
    return main(args)
