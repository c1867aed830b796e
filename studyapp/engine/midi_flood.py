"""``studyapp bench midi``: the live engine under a flood of MIDI control changes.

A second process floods the engine's virtual JACK MIDI input with control
changes on the LPD8's eight knobs (CC 1-8, channel 1) at ``--rate`` messages
per second for ``--seconds``, the knobs in turn, each message a new value; its
last message on each knob is that knob's *final value*. The engine runs at
5 kHz, timer-paced (no audio: ``null``), knob 1 setting F_max, as ``studyapp
live`` does. Per run the bench reports:

- ``deadline_misses``: blocks the worker finished after their deadline;
- ``events_dropped``: events the worker wrote to its event ring that the parent
  never read (the ring overflowed: ``EventRing.lost``);
- ``finals_missing``: knobs whose final value never reached the parent as a
  control event, plus 1 if F_max in the loop is not knob 1's final value;
- ``sent``, ``midi_received`` (messages the worker took from its MIDI input)
  and ``control_events`` (control events the parent received);
- ``midi_overflows``: polls that found rtmidi's input queue full (it may have
  dropped messages then; see midi.py);
- ``overruns``: misses whose block alone took longer than its period on the CPU
  (the engine's share; the rest are the machine's, see worker.py);
- ``quiet_deadline_misses``: the misses of the same engine run as long without
  a flood just before, the machine's background on a shared computer.

Runs are repeated (``--runs``, default 3) and the figures given as medians.
The bench starts its own JACK server with the dummy driver (``jackd`` from
Debian's jackd2, as in the tests), under a private name, and stops it after.
Timing depends on the machine and what else runs on it: a measurement, never a
test.
"""

import contextlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

import numpy as np

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.events import Applied
from studyapp.errors import ParameterError, UserError
from studyapp.model.controls import LIVE_RANGE, FmaxKnob, knob_value
from studyapp.model.sources import LVT_SENSOR

KNOBS = 8
JACK_RATE = 48000
JACK_PERIOD = 1024  # frames: tests/engine/conftest.py explains why not 256 on a loaded VM

SENDER = textwrap.dedent("""
    import json, sys, time
    import rtmidi
    rate, seconds, knobs = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
    BATCH = max(1, int(rate / 1000))  # messages per millisecond
    out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "midi-flood")
    ports = [i for i, name in enumerate(out.get_ports()) if "studyapp MIDI in" in name]
    if not ports:
        sys.exit("no studyapp MIDI input among " + repr(out.get_ports()))
    out.open_port(ports[0])
    time.sleep(0.3)
    total = int(rate * seconds)
    final = {}
    start = time.monotonic()
    for i in range(total):
        if i % BATCH == 0:  # paced in batches: a wake-up per message would load the machine, not the engine
            wait = start + i / rate - time.monotonic()
            if wait > 0:
                time.sleep(wait)
        knob = 1 + i % knobs
        value = (i // knobs * 37 + 11 * knob) % 128
        out.send_message([0xB0, knob, value])
        final[knob] = value
    took = time.monotonic() - start
    time.sleep(0.3)
    out.close_port()
    out.delete()
    print(json.dumps({"sent": total, "seconds": took, "final": final}))
""")


@contextlib.contextmanager
def dummy_jack():
    """A private JACK server with the dummy driver; ``JACK_DEFAULT_SERVER`` names it meanwhile."""

    jackd, wait = shutil.which("jackd"), shutil.which("jack_wait")
    if jackd is None or wait is None:
        raise UserError("bench midi: jackd and jack_wait not found: allowed is a machine with Debian's jackd2 "
                        "(scripts/system-deps.txt)")
    name = f"studyapp-bench-{os.getpid()}"
    saved = {k: os.environ.get(k) for k in ("JACK_DEFAULT_SERVER", "JACK_NO_START_SERVER")}
    os.environ["JACK_DEFAULT_SERVER"] = name
    os.environ["JACK_NO_START_SERVER"] = "1"
    log = tempfile.TemporaryFile()
    server = None
    try:
        for flag in ("-R", "-r"):  # real-time scheduling when the machine allows it
            server = subprocess.Popen([jackd, "-n", name, flag, "-d", "dummy", "-r", str(JACK_RATE),
                                       "-p", str(JACK_PERIOD)], stdout=log, stderr=subprocess.STDOUT)
            if _ready(wait, name, server):
                break
            server.kill()
            server.wait()
            server = None
        if server is None:
            log.seek(0)
            tail = log.read().decode("utf-8", "replace").strip().splitlines()[-1:] or ["no output"]
            raise UserError(f"bench midi: the dummy JACK server did not start ({tail[0]})")
        yield name
    finally:
        if server is not None:
            server.terminate()
            try:
                server.wait(10)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        log.close()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _ready(wait, name, server, timeout=15.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if server.poll() is not None:
            return False
        check = subprocess.run([wait, "-c", "-s", name], capture_output=True, text=True)
        if check.stdout.strip() == "running":
            return True
        time.sleep(0.1)
    return False


def _engine():

    return Engine(EngineConfig(rate=5000.0, source=LVT_SENSOR, fmax=0.5, audio="null", midi="virtual")).start()


def quiet(seconds):
    """Deadline misses of the engine run for ``seconds`` with its MIDI input open and silent."""
    engine = _engine()
    try:
        time.sleep(seconds)
    finally:
        summary = engine.stop() or {}
    return summary.get("deadline_misses", -1)


def flood(rate, seconds, progress=print):
    """One run: the engine under ``rate`` control changes per second for ``seconds``; the figures."""


    background = quiet(seconds)
    engine = _engine()
    controls = []
    try:
        sender = subprocess.Popen([sys.executable, "-c", SENDER, str(rate), str(seconds), str(KNOBS)],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        while sender.poll() is None:
            controls += engine.controls()
            time.sleep(0.05)
        out, err = sender.communicate()
        if sender.returncode != 0:
            raise RuntimeError(f"bench midi: the sender failed: {err.strip().splitlines()[-1:]}")
        sent = json.loads(out)
        time.sleep(0.2)
        controls += engine.controls()
        fmax = engine.status()["fmax"]
    finally:
        summary = engine.stop() or {}
    last = {}
    for event in controls:
        if isinstance(event, Applied):
            last[event.control] = event.value
    final = {f"knob{k}": v for k, v in ((int(k), v) for k, v in sent["final"].items())}
    missing = sum(1 for knob, value in final.items() if last.get(knob) != knob_value(value))
    missing += 0 if np.isclose(fmax, FmaxKnob(*LIVE_RANGE).fmax(final["knob1"])) else 1
    result = {
        "rate": rate, "seconds": sent["seconds"], "sent": sent["sent"],
        "midi_received": summary.get("midi_messages", 0), "control_events": len(controls),
        "midi_overflows": summary.get("midi_overflows", 0),
        "events_dropped": engine.events_dropped, "finals_missing": missing,
        "deadline_misses": summary.get("deadline_misses", -1), "overruns": summary.get("overruns", -1),
        "quiet_deadline_misses": background, "load_max": summary.get("load_max", 0.0),
        "faults": list(engine.faults),
    }
    progress(f"bench midi: {result['sent']} messages in {result['seconds']:.2f} s: received "
             f"{result['midi_received']}, control events {result['control_events']}, dropped "
             f"{result['events_dropped']}, finals missing {missing}, deadline misses {result['deadline_misses']} "
             f"(overruns {result['overruns']}; {background} without the flood)")
    return result


def run_cli(args):


    if not 1 <= args.rate <= 100_000:
        raise ParameterError(f"--rate {args.rate:g}: allowed is 1 to 100000 messages per second")
    if not 0 < args.seconds <= 600:
        raise ParameterError(f"--seconds {args.seconds:g}: allowed is more than 0 and at most 600")
    if not 1 <= args.runs <= 20:
        raise ParameterError(f"--runs {args.runs}: allowed is 1 to 20")

    def progress(text):
        print(text, file=sys.stderr, flush=True)

    with dummy_jack():
        runs = [flood(args.rate, args.seconds, progress) for _ in range(args.runs)]
    keys = ("sent", "midi_received", "control_events", "midi_overflows", "events_dropped", "finals_missing",
            "deadline_misses", "overruns", "quiet_deadline_misses")
    medians = {k: statistics.median(r[k] for r in runs) for k in keys}
    result = {"rate": args.rate, "seconds": args.seconds, "runs": runs, "median": medians}
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        print(f"MIDI flood, {args.rate:g} control changes/s for {args.seconds:g} s, median of {args.runs} runs: "
              f"{medians['deadline_misses']:g} deadline misses ({medians['overruns']:g} overruns; "
              f"{medians['quiet_deadline_misses']:g} without the flood), {medians['events_dropped']:g} events dropped, "
              f"{medians['finals_missing']:g} final values missing "
              f"({medians['control_events']:g} control events from {medians['midi_received']:g} messages)")
    return 0
