"""The parent's handle on the real-time engine: start, command, watch, stop.

    with Engine(EngineConfig(rate=5000, estimators={"KALLEV": {}}, source="KALLEV")) as engine:
        engine.send(SetFmax(2.0))  # a command (engine/commands.py), applied at the next block
        engine.status()            # the shared status block (status.NUMBERS, status.TEXTS)
        engine.telemetry(5000)     # newest samples of every channel, from the shared rings
        engine.controls()          # controls the worker applied since the last call (events.Applied)

The parent creates the shared memory (a ring for the telemetry, the status
block, a ring of events from the worker), spawns the force guard
(``guard.main``, a process of its own: nothing the parent does can delay it)
and the worker (``worker.main``), and, once the worker reports ready, runs a
watchdog thread (engine/watchdog.py) that drains the worker's events and
reports faults: a dead or hung worker, a dead guard. The worker in turn
switches its own force off when the guard's heartbeat is older than
``guard_timeout``. ``stop()`` asks the worker to finish, waits for it while it
shows signs of life, kills it if it will not go, ends the guard and unlinks
the shared memory: no orphan process, no leaked segment.

An engine whose MIDI input waits for its controller (JACK, ``--midi first``
or a port name, none there at the start) gets a ``MidiHotplug`` thread that
connects the controller once it is plugged in (``midi_hotplug.py``).

The worker's events (control events, notices, faults) pass through a ring of
``event_ring.SLOTS`` slots; should the watchdog fall a whole ring behind, the
events overwritten unread are counted in ``events_dropped`` (also in
``status()``), never silently lost.
"""

import contextlib
import multiprocessing
import os
import threading
import time

from studyapp.device.link_probe import probe as probe_link
from studyapp.device.link_open import is_link
from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine import guard, midi_hotplug, parent_death, shm_names
from studyapp.engine.audio.sinks import parse as parse_audio
from studyapp.engine.config import EngineConfig
from studyapp.engine.event_ring import EventRing
from studyapp.engine.ring import Ring
from studyapp.engine.status import StatusBlock
from studyapp.engine.telemetry import channels_for
from studyapp.engine.watchdog import POLL, Watchdog
from studyapp.errors import EngineError, ParameterError
from studyapp.model.limits import GESTURES
from studyapp.model.sources import with_pseudo_sources

__all__ = ["Engine", "EngineError"]

START_TIMEOUT = 120.0  # s for the worker to import, compile and prime


class Engine(Watchdog):
    def __init__(self, config=None, on_fault=None, on_notice=None, on_device=None):
        self.config = config or EngineConfig()
        self.on_fault = on_fault
        self.on_notice = on_notice or (lambda notice: None)
        self.on_device = on_device or (lambda record: None)  # events.DeviceInfo and DeviceHealth, as they come
        self.names = self._validate()
        self.faults = []
        self._cleared = 0  # how many of ``faults`` a clear has answered (``faults_since_clear``)
        self.fault_time = None  # time.monotonic() when the watchdog or the worker reported the first fault
        self.tripped = False  # the watchdog found the worker dead or hung
        self.info = {}
        self.summary = None
        self.process = None
        self.guard = None  # the force guard's process (guard.py)
        self.ring = None
        self.status_block = None
        self._controls = []
        self._lock = threading.Lock()
        self._event_lock = threading.Lock()
        self._stop_watch = threading.Event()
        self._watchdog = None
        self._hotplug = None
        self._stopping = False
        self.events_dropped = 0  # events the worker wrote that the ring overwrote before we read them

    # set-up ----------------------------------------------------------------
    def _validate(self):
        """Cheap checks in the parent, so a bad setting is a one-line error before any process starts."""
        from studyapp.estimators import Bank
        from studyapp.estimators.spec import validate_rate
        from studyapp.model import calibration
        from studyapp.model.playable import check_playable

        c = self.config
        c.rate = validate_rate(c.rate)
        check_playable(c.rate, calibration.F0 if c.f0 is None else c.f0)
        estimators = c.estimators if isinstance(c.estimators, dict) else {n: {} for n in c.estimators}
        if is_link(c.device):
            found = probe_link(c.device, c.rate, c.device_packet, c.device_calibration, c.device_latency,
                               c.device_ramp_ms)
            if found["loop"] == "device":
                # the device's loop runs its own estimators: the engine's loop (its shadow) runs the same, in
                # INFO's order, with the protocol's parameters where it names them (a difference is refused
                # at the first block: loop_link.py checks the parameter image)
                from studyapp.device.loop_bank import names_of

                estimators = {n: estimators.get(n, {}) for n in names_of(found["estimator_kinds"])}
        names = Bank(c.rate, estimators).names
        c.estimators = dict(zip(names, estimators.values()))
        allowed = with_pseudo_sources(names)
        if c.source not in allowed:
            raise ParameterError(f"source {c.source!r}: allowed are {', '.join(allowed)}")
        fmax = float(c.fmax)
        if not 0.0 <= fmax <= c.safety.fmax_ceiling:
            raise ParameterError(f"fmax = {c.fmax}: allowed is 0 to {c.safety.fmax_ceiling:g} N (the safety ceiling)")
        if c.gesture not in GESTURES or c.gesture == "playback":
            live = [g for g in GESTURES if g != "playback"]  # playback needs a recorded trajectory
            raise ParameterError(f"gesture {c.gesture!r}: allowed are {', '.join(live)}")
        parse_audio(c.audio)
        c.check_sizes()
        return names

    def start(self, timeout=START_TIMEOUT):
        from studyapp.engine.worker import REALTIME_PRIORITY, main

        c = self.config
        capacity = max(int(c.telemetry_seconds * c.rate), 4 * c.block_size())
        shm_names.remove_stale()  # what a killed run (its resource tracker killed too) left in /dev/shm
        shm_names.name_semaphores()
        self.ring = Ring.create(channels_for(self.names), capacity)
        self.status_block = StatusBlock.create()
        ctx = multiprocessing.get_context("spawn")
        self._commands = ctx.Queue()
        self._events = EventRing.create()
        # each child dies with this process from its first instant (parent_death.py)
        entry, args = parent_death.spawn_args(guard.main, self.status_block.name, c.hang_timeout,
                                              REALTIME_PRIORITY + 1 if c.realtime else None, self.ring.spec, os.getpid())
        self.guard = ctx.Process(target=entry, name="studyapp-guard", daemon=True, args=args)
        self.guard.start()
        entry, args = parent_death.spawn_args(main, c, self.ring.spec, self.status_block.name)
        self.process = ctx.Process(target=entry, name="studyapp-engine", daemon=True, args=args,
                                   kwargs={"commands": self._commands, "events_name": self._events.name})
        self.process.start()
        deadline = time.monotonic() + timeout
        while True:
            event = self._next_event(min(0.05, max(0.0, deadline - time.monotonic())))
            if event is not None:
                if isinstance(event, ev.Ready):
                    self.info = event.info
                    break
                if isinstance(event, ev.Failed):
                    self._cleanup()
                    raise EngineError(f"engine: {event.text}")
                self._handle(event)
            elif not self.process.is_alive():
                code = self.process.exitcode
                self._cleanup()
                raise EngineError(f"engine: the worker exited while starting (exit code {code})")
            if time.monotonic() > deadline:
                self._cleanup()
                raise EngineError(f"engine: the worker did not start within {timeout:g} s")
        self._watchdog = threading.Thread(target=self._watch, name="studyapp-watchdog", daemon=True)
        self._watchdog.start()
        inlet = self.info.get("midi_inlet")
        if inlet and midi_hotplug.available():
            self._hotplug = midi_hotplug.MidiHotplug(c.midi.strip(), inlet, self._midi_port).start()
        return self

    def __enter__(self):
        return self.start() if self.process is None else self

    def __exit__(self, *exc):
        self.stop()

    # commands --------------------------------------------------------------
    def send(self, command):
        """Queue a command (``commands.Command``) for the worker's next block boundary."""
        if self.process is None or not self.process.is_alive():
            raise EngineError("engine: not running")
        if isinstance(command, cmd.SetSource):
            allowed = with_pseudo_sources(self.names)
            if command.name not in allowed:
                raise ParameterError(f"source {command.name!r}: allowed are {', '.join(allowed)}")
        self._commands.put(command)

    def _midi_port(self, port):
        with contextlib.suppress(EngineError):
            self.send(cmd.MidiPort(port or ""))

    def clear_fault(self):
        """Unlatch a safety fault in the worker; after a watchdog trip only a restart helps."""
        if self.tripped:
            raise EngineError("engine: the watchdog stopped this engine; start a new one")
        self.send(cmd.ClearFault())
        with self._lock:
            self._cleared = len(self.faults)

    def faults_since_clear(self):
        """The faults reported since the last ``clear_fault`` (all of them before one): what stopped the
        engine when it fails, not an emergency stop cleared long before (issue 41, item 12)."""
        with self._lock:
            return self.faults[self._cleared:]

    # reading ---------------------------------------------------------------
    def _shared(self):
        if self.status_block is None:
            raise EngineError("engine: not running")

    def status(self):
        """The worker's status block (status.NUMBERS, status.TEXTS) and ``events_dropped`` (parent side)."""
        self._shared()
        snap = self.status_block.read()
        snap["events_dropped"] = self.events_dropped
        return snap

    def telemetry(self, n=None, since=None):
        """Telemetry as ``{channel: array}`` plus ``"estimates": {name: array}``, ``"start"``, ``"end"``.

        ``n``: the newest n samples; ``since``: every sample from that sample
        number on (as far as the ring still holds them).
        """
        self._shared()
        if since is not None:
            data, start, end = self.ring.read_since(since)
        else:
            data, start, end = self.ring.read_since(0, limit=n)
        out = {"start": start, "end": end, "estimates": {}}
        for i, channel in enumerate(self.ring.channels):
            if channel.startswith("estimate:"):
                out["estimates"][channel[9:]] = data[i]
            else:
                out[channel] = data[i]
        return out

    def controls(self):
        """Controls the worker took since the last call: ``events.Applied`` and ``events.Learned`` records.

        An ``Applied`` record names the control and its value in [0, 1], its
        arrival (``time.monotonic()``), the seconds from arrival to the start of
        the block that applied its action (``None`` when the control has no
        action), how many block boundaries it waited for (0 or 1 unless the
        engine fell behind), that block's number (its first sample is
        ``block * config.block``) and the mapping's trial tag.
        """
        with self._lock:
            out, self._controls = self._controls, []
        return out

    @property
    def alive(self):
        return self.process is not None and self.process.is_alive() and not self.tripped

    @property
    def force_output(self):
        """The force the device puts out now (N): 0 once the worker is gone, hung or faulted."""
        if not self.alive:
            return 0.0
        snap = self.status()
        if snap["fault_latched"] or not self.status_block.force_enable:
            return 0.0
        data, _ = self.ring.read_latest(1)
        return float(data[self.ring.index("force"), -1]) if data.shape[1] else 0.0

    # watchdog --------------------------------------------------------------
    def _next_event(self, timeout):
        if self._events is None:
            return None
        end = time.monotonic() + timeout
        while True:
            with self._event_lock:  # the watchdog and stop() may both be reading
                event = self._events.get() if self._events is not None else None
                if self._events is not None:
                    self.events_dropped = self._events.lost
            if event is not None or time.monotonic() >= end:
                return event
            time.sleep(min(POLL / 2, max(0.0, end - time.monotonic())))

    def _handle(self, event):
        if isinstance(event, ev.Notice):
            self.on_notice(event)
        elif isinstance(event, ev.Fault):
            self._fault(event.text, event.when)
        elif isinstance(event, ev.Failed):
            self._fault(f"worker error: {event.text}", time.monotonic())
        elif isinstance(event, (ev.Applied, ev.Learned)):
            with self._lock:
                self._controls.append(event)
        elif isinstance(event, ev.Stopped):
            self.summary = event.summary
        elif isinstance(event, (ev.DeviceInfo, ev.DeviceHealth)):
            self.on_device(event)

    def _fault(self, text, when):
        with self._lock:
            self.faults.append(text)
            if self.fault_time is None:
                self.fault_time = when
        if self.on_fault is not None:
            self.on_fault(text)

    # shutting down ---------------------------------------------------------
    def stop(self, timeout=10.0):
        """Stop the worker (politely, then by force), unlink the shared memory; returns its summary."""
        if self.process is None:
            return self.summary
        self._stopping = True
        if self._hotplug is not None:
            self._hotplug.stop()
            self._hotplug = None
        if self.process.is_alive():
            with contextlib.suppress(Exception):
                self._commands.put(cmd.Stop())
            end = time.monotonic() + timeout
            heard = time.monotonic()
            while self.process.is_alive() and time.monotonic() < end and not self.stalled(heard):
                event = self._next_event(0.05)
                if event is not None:
                    self._handle(event)
                    heard = time.monotonic()
            if self.process.is_alive():
                self.process.kill()  # SIGKILL: a stopped worker would never handle SIGTERM
        self.process.join(5.0)
        self._end_guard()
        self._stop_watch.set()
        if self._watchdog is not None and self._watchdog is not threading.current_thread():
            self._watchdog.join(2.0)
        while (event := self._next_event(0)) is not None:
            self._handle(event)
        self._cleanup()
        return self.summary

    def _end_guard(self):
        if self.guard is not None:
            if self.guard.is_alive():
                self.guard.kill()
            self.guard.join(5.0)

    def _cleanup(self):
        if self.process is not None and self.process.is_alive():
            self.process.kill()
            self.process.join(5.0)
        self._end_guard()
        self.guard = None
        commands = getattr(self, "_commands", None)
        if commands is not None:
            commands.close()
            commands.cancel_join_thread()
        with self._event_lock:
            if getattr(self, "_events", None) is not None:
                self._events.close()
                self._events = None
        if self.ring is not None:
            self.ring.close()
        if self.status_block is not None:
            self.status_block.close()
        self.ring = None
        self.status_block = None
        self.process = None
