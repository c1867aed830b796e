"""MIDI hot-plug on JACK: the parent watches for the controller and connects it to the worker's inlet.

An engine asked for ``--midi first`` (or a port name) that found no such port
when it started waits with an input port of its own, the *inlet*
(``midi.MidiInput.waiting``). Every ``midi.RESCAN`` seconds a thread in the
parent lists JACK's MIDI output ports (``jack_lsp``), and once one matches it
connects that port to the inlet (``jack_connect``) and tells the worker
(``on_change(port)``: the engine sends ``commands.MidiPort``), so a controller
plugged in after the start acts within the period plus one block. A
connected port that disappears is reported (``on_change(None)``; JACK drops
the connection itself) and looked for again.

The work is done by JACK's own command-line tools in a child process: the
parent's Python never waits on the JACK server with the GIL held (python-rtmidi
would), and the worker, whose loop is real-time, is never involved beyond one
command. A scan costs a fork and exec every 2 s in the parent.
"""

import shutil
import subprocess
import threading

from studyapp.engine.midi import RESCAN, match_port

TOOL_TIMEOUT = 5.0  # s: a JACK server that does not answer the tools in this long is skipped until the next scan


def midi_outputs():
    """JACK's MIDI output ports (sources a controller sends from), in the server's order; [] without a server."""
    try:
        done = subprocess.run(["jack_lsp", "-p", "-t"], capture_output=True, text=True, timeout=TOOL_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired):
        return []
    ports, name, properties = [], None, ""
    for line in done.stdout.splitlines():
        if not line.startswith(("\t", " ")):
            name, properties = line.strip(), ""
        elif line.strip().startswith("properties:"):
            properties = line
        elif "midi" in line and "output" in properties and name:
            ports.append(name)
    return ports


def connect(source, destination):
    """Connect two JACK ports; True when connected."""
    try:
        done = subprocess.run(["jack_connect", source, destination], capture_output=True, timeout=TOOL_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return done.returncode == 0


def available():
    return shutil.which("jack_lsp") is not None and shutil.which("jack_connect") is not None


class MidiHotplug:
    """Watches for ``spec``'s port and keeps it connected to ``inlet``; ``on_change(port or None)``."""

    def __init__(self, spec, inlet, on_change, period=RESCAN):
        self.spec = spec
        self.inlet = inlet
        self.on_change = on_change
        self.period = period
        self.port = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="studyapp-midi-hotplug", daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _run(self):
        while not self._stop.wait(self.period):
            self.scan()

    def scan(self):
        """One look at the ports: connect a new controller, or notice the connected one gone."""
        own = self.inlet.split(":", 1)[0] + ":"
        ports = [p for p in midi_outputs() if not p.startswith(own)]
        if self.port is not None:
            if self.port in ports:
                return
            self.port = None
            self.on_change(None)
        match = match_port(self.spec, ports)
        if match is not None and connect(match, self.inlet):
            self.port = match
            self.on_change(match)

    def stop(self):
        self._stop.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(TOOL_TIMEOUT + 1.0)
