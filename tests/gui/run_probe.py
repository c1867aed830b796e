"""``studyapp run`` (its GUI path, as ``make run``'s ``studyapp gui`` and a lab's ``studyapp run`` take it),
watched from inside: once the session's first step is on screen, one JSON line on stdout says where the
console, its session buttons and the participant's window are, then (``--then exit``) the console shuts
down, or (``--then wait``) the process waits to be killed, as a crash would end it.

    python -m tests.gui.run_probe {exit|wait} RUN_ARGS...
"""

import json
import sys

from studyapp.cli import main as cli


def rect(widget, global_=True):
    from PySide6.QtCore import QPoint

    top = widget.mapToGlobal(QPoint(0, 0)) if global_ else widget.pos()
    return [top.x(), top.y(), widget.width(), widget.height()]


def report(console):
    from PySide6.QtWidgets import QApplication

    screen = console.screen()
    p = console.participant_window
    c = console.controller
    return {
        "screen": [screen.geometry().width(), screen.geometry().height()],
        "available": [screen.availableGeometry().x(), screen.availableGeometry().y(),
                      screen.availableGeometry().width(), screen.availableGeometry().height()],
        "console": [console.frameGeometry().x(), console.frameGeometry().y(),
                    console.frameGeometry().width(), console.frameGeometry().height()],
        "buttons": {name: rect(getattr(console, name)) for name in
                    ("start_button", "pause_button", "abort_button", "stop_button")},
        "blind": rect(console.blind),
        "participant": {"visible": p.isVisible(), "full_screen": p.isFullScreen(), "geometry": rect(p),
                        "screen": QApplication.screens().index(p.screen()) if p.screen() else None},
        "state": str(c.state), "step": c.runner.trial.step if c.runner and c.runner.trial else None,
        "audio": c.audio, "midi": c.midi,
    }


def main(then, argv):
    from PySide6.QtCore import QTimer

    import studyapp.gui.app as app

    real_main = app.main

    def watched(args):
        qt = app.application()
        timer = QTimer()
        timer.setInterval(50)

        def look():
            consoles = [w for w in qt.topLevelWidgets() if type(w).__name__ == "Console"]
            if not consoles or not consoles[0].controller.playing:
                return
            timer.stop()
            for _ in range(20):
                qt.processEvents()
            print(json.dumps(report(consoles[0])), flush=True)
            if then == "exit":
                consoles[0].shut_down()

        timer.timeout.connect(look)
        timer.start()
        return real_main(args)

    app.main = watched
    return cli(["run", *argv])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2:]))
