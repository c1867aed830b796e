"""``studyapp bench force-cut``: how long a stopped worker keeps its force while the parent is busy.

One try: start an engine (simulated device, LVT, 1 N, null audio), let it run,
stop its worker with SIGSTOP, and keep the parent busy for ``--busy`` seconds
(default 2 s) in one of two ways:

- ``python``: a pure-Python loop (bytecode: the interpreter hands its lock to
  other threads every switch interval);
- ``gil``: one call into C that never lets go of the interpreter's lock
  (libc's ``usleep`` through ``ctypes.PyDLL``), a parent that has stopped
  answering altogether: none of its threads runs until the call returns.

Two more modes stop or kill the engine's *owner* instead, the process that
started it (the console, ``live``): ``owner-stop`` (SIGSTOP) and ``owner-kill``
(SIGKILL). The owner is a process of its own that starts an engine and waits;
this process stops or kills it and watches the word itself. The guard sees
the owner stopped or gone (engine/guard.py) and cuts the force.

The force-cut time is from the SIGSTOP to the moment the ``force_enable`` word in
the status block reads 0 (the worker computes no force from then on: it reads
the word before and after every block, engine/safety.py). An observer process
polls the word every 0.2 ms and reports the moment it falls, so the figure does
not depend on the busy parent. The worker is killed afterwards, and a new
engine starts for the next try. The result lists every try and the median and
maximum per mode; it is a measurement on this machine under its load, never a
test.
"""

import ctypes
import json
import multiprocessing
import os
import signal
import statistics
import sys
import time

from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.status import StatusBlock
from studyapp.errors import ParameterError

MODES = ("python", "gil")
OWNER_MODES = ("owner-stop", "owner-kill")
START_WAIT = 120.0  # s an owner may take to start its engine on a loaded machine
OWNER_WORDS = {"owner-stop": "owner stopped (SIGSTOP)", "owner-kill": "owner killed (SIGKILL)"}


def _observe(status_name, ready, out, limit):
    """In its own process: report time.monotonic() when ``force_enable`` falls (or None after ``limit`` s)."""

    status = StatusBlock.attach(status_name)
    try:
        ready.send(True)
        end = time.monotonic() + limit
        while status.force_enable and time.monotonic() < end:
            time.sleep(0.0002)
        out.send(None if status.force_enable else time.monotonic())
    finally:
        status.close()


def _busy_python(seconds):
    end = time.monotonic() + seconds
    total = 0
    while time.monotonic() < end:
        for i in range(1000):
            total += i * i
    return total


def _busy_gil(seconds):
    """Sleep in C with the interpreter's lock held: ``PyDLL`` calls keep the GIL, unlike ``CDLL``'s."""

    ctypes.PyDLL(None).usleep(int(seconds * 1e6))


def one_try(mode, busy=2.0):
    """One SIGSTOP while the parent is busy; returns the force-cut time in s (None if the force stayed on,
    "void" if it was cut before the stop: the worker starved by a loaded machine, retried by ``measure``)."""

    ctx = multiprocessing.get_context("spawn")
    engine = Engine(EngineConfig(rate=5000.0, source="LVT", fmax=1.0, audio="null", midi="none")).start()
    try:
        deadline = time.monotonic() + 10.0
        while engine.status()["samples"] < 1000 and time.monotonic() < deadline:
            time.sleep(0.01)
        ready_in, ready_out = ctx.Pipe(duplex=False)
        result_in, result_out = ctx.Pipe(duplex=False)
        observer = ctx.Process(target=_observe, args=(engine.status_block.name, ready_out, result_out, busy + 5.0),
                               daemon=True)
        observer.start()
        ready_in.recv()
        if not engine.status_block.force_enable:  # cut already (the machine starved the worker): no try
            observer.kill()
            return "void"
        stopped = time.monotonic()
        os.kill(engine.process.pid, signal.SIGSTOP)
        (_busy_gil if mode == "gil" else _busy_python)(busy)
        cut = result_in.recv()
        observer.join(5.0)
        return None if cut is None else cut - stopped
    finally:
        if engine.process is not None:
            os.kill(engine.process.pid, signal.SIGKILL)
        engine.stop()


def _own_an_engine(out):
    """The owner process: start an engine, tell its status block and processes, then wait to be stopped."""
    engine = Engine(EngineConfig(rate=5000.0, source="LVT", fmax=1.0, audio="null", midi="none")).start()
    deadline = time.monotonic() + 10.0
    while engine.status()["samples"] < 1000 and time.monotonic() < deadline:
        time.sleep(0.01)
    out.send((engine.status_block.name, engine.process.pid, engine.guard.pid))
    time.sleep(120.0)


def owner_try(mode, limit=5.0):
    """One stop or kill of an engine's owner: ``(cut time in s or None, reason)``; "void" as ``one_try``."""
    ctx = multiprocessing.get_context("spawn")
    told_in, told_out = ctx.Pipe(duplex=False)
    owner = ctx.Process(target=_own_an_engine, args=(told_out,))  # not a daemon: it starts an engine
    owner.start()
    told_out.close()  # the owner's end: if it dies before telling, recv ends instead of waiting for ever
    pids = []
    try:
        if not told_in.poll(START_WAIT):
            raise RuntimeError(f"the owner's engine did not start within {START_WAIT:g} s")
        name, *pids = told_in.recv()
        status = StatusBlock.attach(name)
        try:
            if not status.force_enable:
                return "void", None
            stopped = time.monotonic()
            os.kill(owner.pid, signal.SIGSTOP if mode == "owner-stop" else signal.SIGKILL)
            end = stopped + limit
            while status.force_enable and time.monotonic() < end:
                time.sleep(0.0002)
            cut = None if status.force_enable else status.force_off_time - stopped
            return cut, status.force_off_reason
        finally:
            status.close()
    finally:
        for pid in (*pids, owner.pid):
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        owner.join(5.0)


def measure_owner(tries=10, modes=OWNER_MODES, progress=print):
    summary = {}
    for mode in modes:
        cuts, void = [], 0
        while len(cuts) < tries:
            cut, reason = owner_try(mode)
            if cut == "void" and void < 5 * tries:
                void += 1
                continue
            cuts.append(None if cut == "void" else cut)
            progress(f"try {len(cuts)}/{tries} {mode}: " + ("force never cut" if cut is None
                                                            else f"{1e3 * cut:.1f} ms ({reason})"))
        seen = [c for c in cuts if c is not None]
        summary[mode] = {
            "tries": len(cuts), "never_cut": len(cuts) - len(seen), "void_tries": void,
            "median_ms": 1e3 * statistics.median(seen) if seen else None,
            "max_ms": 1e3 * max(seen) if seen else None,
            "cuts_ms": [None if c is None else round(1e3 * c, 2) for c in cuts],
        }
    return {"modes": summary}


def measure(tries=20, busy=2.0, modes=MODES, progress=print):
    runs = {mode: [] for mode in modes}
    void = {mode: 0 for mode in modes}
    for i in range(tries):
        for mode in modes:
            cut = one_try(mode, busy)
            while cut == "void" and void[mode] < 5 * tries:
                void[mode] += 1
                progress(f"try {i + 1}/{tries} {mode}: the force was cut before the stop (a loaded machine); again")
                cut = one_try(mode, busy)
            runs[mode].append(None if cut == "void" else cut)
            progress(f"try {i + 1}/{tries} {mode}: " + ("force never cut" if cut is None else f"{1e3 * cut:.1f} ms"))
    summary = {}
    for mode, cuts in runs.items():
        seen = [c for c in cuts if c is not None]
        summary[mode] = {
            "tries": len(cuts), "never_cut": len(cuts) - len(seen), "void_tries": void[mode],
            "median_ms": 1e3 * statistics.median(seen) if seen else None,
            "max_ms": 1e3 * max(seen) if seen else None,
            "cuts_ms": [None if c is None else round(1e3 * c, 2) for c in cuts],
        }
    return {"busy_s": busy, "modes": summary}


def run_cli(args):

    if not 1 <= args.tries <= 1000:
        raise ParameterError(f"--tries {args.tries}: allowed is an integer from 1 to 1000")
    if not 0.0 < args.busy <= 60.0:
        raise ParameterError(f"--busy {args.busy:g}: allowed is a number of seconds above 0 and up to 60")
    say = lambda text: print(text, file=sys.stderr, flush=True)  # noqa: E731
    if args.mode in ("owner", *OWNER_MODES):
        result = measure_owner(args.tries, OWNER_MODES if args.mode == "owner" else (args.mode,), progress=say)
    else:
        result = measure(args.tries, args.busy, MODES if args.mode == "both" else (args.mode,), progress=say)
    if args.json:
        print(json.dumps(result))
    else:
        for mode, s in result["modes"].items():
            busy = f"parent busy ({mode}) {args.busy:g} s" if mode in MODES else OWNER_WORDS[mode]
            print(f"force cut, {busy}: median {s['median_ms']} ms, "
                  f"max {s['max_ms']} ms over {s['tries']} tries ({s['never_cut']} never cut)")
    return 0
