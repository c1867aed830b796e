"""A screenshot of the console's set-up side with a device on a link, for docs/gui.md and docs/devices.md.

    PYTHONPATH=. python scripts/device_panel_screenshot.py FILE.png [--protocol FILE] [--seeds N]
        [--latency SAMPLES]

Starts ``studyapp device-emulator`` on a pty in a temporary folder, runs the console (offscreen Qt unless
QT_QPA_PLATFORM says otherwise; audio and MIDI off) on it with the link latency ``--latency`` (default 5 samples,
the host's default), waits for the device's handshake in the Apparatus panel and for the rig check's prediction
(``--seeds``, default 5: the real model, 20-25 s of one core for sinclair2014's nine conditions on an idle
machine), and writes the set-up panel's own rendering (``studyapp.gui.screenshot.save_widget``). Prints the path.
"""

import argparse
import functools
import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]


def wait(app, predicate, what, timeout):
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            sys.exit(f"device_panel_screenshot: timed out waiting for {what}")
        app.processEvents()
        time.sleep(0.02)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file")
    parser.add_argument("--protocol", default=str(ROOT / "protocols" / "sinclair2014.toml"))
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--latency", type=int, default=5)
    args = parser.parse_args()

    from studyapp.device.emulator_process import EmulatorProcess
    from studyapp.gui.app import application
    from studyapp.gui.console import Console
    from studyapp.gui.screenshot import save_widget
    from studyapp.live import rig_check
    from studyapp.live.controller import SessionController

    app = application()
    with tempfile.TemporaryDirectory() as folder, EmulatorProcess(Path(folder) / "studyapp-device",
                                                                  "--watchdog-ms", 200) as emulator:
        controller = SessionController(audio="null", midi="none", device=emulator.link, hang_timeout=0.5)
        controller.apparatus.device_options = {"device_latency": args.latency, "device_silence": 0.5}
        console = Console(controller, predict=functools.partial(rig_check.predict, seeds=args.seeds))
        console.resize(1366, 900)
        console.show()
        try:
            if not console.choose_protocol(args.protocol):
                sys.exit(f"device_panel_screenshot: {console.setup.error.text()}")
            console.device_panel.show_choice(emulator.link)
            panel = console.device_panel
            wait(app, lambda: "serial" in panel.summary.text(), "the device's handshake", 300)
            wait(app, lambda: panel.table.isVisibleTo(console), "the rig check's prediction", 3600)
            for _ in range(20):
                app.processEvents()
            if controller.host.state != "running":
                sys.exit(f"device_panel_screenshot: the engine is {controller.host.state}: "
                         f"{console.log.toPlainText()[-500:]}")
            print(save_widget(console.setup, args.file))
        finally:
            console.shut_down()


if __name__ == "__main__":
    main()
