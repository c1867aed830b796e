"""The worker process: the closed loop in real time, block by block.

Started by ``engine.Engine`` with the spawn context (a fresh interpreter: no
inherited locks, threads or Qt state). It builds only what the scene names:
the loop with the active estimators, the audio sink (no audio rendered for a
null sink), the MIDI input if asked for. Then, for block k of B samples at
rate R (period T = B / R):

1. wait for the pacing clock (engine/pacing.py): the audio device's FIFO
   dropping below its lead (the device callback is the clock), or else the
   monotonic timer reaching t0 + k T;
2. apply every queued command and MIDI control (block boundary), measuring
   the command-to-effect latency: from the command's ``sent`` time (or the
   MIDI message's arrival) to its application, just before this block runs;
3. run the loop for B samples; let the safety layer inspect them;
4. push the audio to the sink, the telemetry to the ring, the status record.

The sink's signal chain (engine/signal_chain.py) is told, with each block,
whether the bow is on the string (silence while it is lifted) and whether the
model's sound jumps at this block (``cut``: a string reset at a trial's start,
a change of velocity source), so that every start, stop and cut fades.

Deadline misses, overruns, stalls and late wake-ups are counted by the block
clock (engine/pacing.py).

The telemetry of each block (engine/telemetry.py) goes to the shared ring.
Knob and pad actions are applied here, in and out of a session, through the
mapping installed last; on-screen controls arrive as ``Control`` commands and
take the same route as MIDI, with soft takeover for a physical knob
(engine/pickup.py).

A MIDI input waiting for its controller (JACK hot-plug, ``midi.py``) is
connected by the parent; a ``MidiPort`` command names the port (or says it
went away), and the status block's ``midi`` text and a notice follow.

The worker stops on a ``Stop`` command, or when its parent dies (it checks the
parent's sentinel every 50 ms, so no orphan keeps running).

It runs its loop only under the force guard's watch (engine/guard.py,
engine/supervision.py): no force once the guard falls silent.
"""

import gc
import importlib
import multiprocessing
import os
import queue
import signal
import sys
import time
import traceback

from studyapp.device.link_open import is_link
from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine import parent_death
from studyapp.engine.audio.recorder import Recordings
from studyapp.engine.audio.sinks import open_sink
from studyapp.engine.device_link import DeviceLink
from studyapp.engine.event_ring import EventRing
from studyapp.engine.midi import ControlMap, open_input
from studyapp.engine.pacing import IDLE, Pacing
from studyapp.engine.pickup import ControlRouting
from studyapp.engine.ring import Ring
from studyapp.engine.safety import Safety
from studyapp.engine.status import StatusBlock
from studyapp.engine.supervision import GuardWatch
from studyapp.engine.telemetry import WITHHELD, Rows, channels_for
from studyapp.model.controls import as_actions

REALTIME_PRIORITY = 5  # below JACK's own threads (10 and 9 by default)

TIMER_TAKES_OVER = "the timer paces the loop now"  # the notice the console follows (its pacing line)


def make_device(config):
    """The configured device: a link (path or URL: studyapp/device/link_device.py, or loop_link.py for a device
    that runs the loop, as its INFO says: device_open.py), a driver from
    ``"module:factory"`` (called with the rate), or ``None`` (the simulated device)."""
    spec = config.device
    if not spec:
        return None
    if is_link(spec):
        from studyapp.device.device_open import open_link_device

        return open_link_device(spec, config.rate, config.link_options())
    module, _, factory = spec.partition(":")
    return getattr(importlib.import_module(module), factory)(config.rate)


def main(config, ring_spec, status_name, commands, events_name):
    """Entry point of the worker process."""
    # Ctrl-C reaches the whole process group; the parent decides when the worker stops.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ.setdefault("JACK_NO_START_SERVER", "1")
    status = StatusBlock.attach(status_name)
    ring = Ring.attach(ring_spec)
    events = EventRing.attach(events_name)
    worker = None
    hard_exit = False
    try:
        worker = Worker(config, ring, status, commands, events)
        worker.run()
    except BaseException as exc:  # noqa: BLE001 - the parent must hear about every way out
        text = f"{type(exc).__name__}: {exc}".splitlines()[0]
        status.set(state="failed", fault=text)
        status.publish(texts=True)
        events.put(ev.Failed(text, traceback.format_exc()[-3000:]))
    finally:
        if worker is not None:
            hard_exit = worker.close()
        ring.close()
        status.close()
        events.close()
    if hard_exit:
        # PortAudio's exit handler would wait for the stuck stream: leave without it
        os._exit(0)


SUMMARY_FAULTS = 20  # the first faults in the summary (its event has a size limit; live re-arms trip after trip)


class Worker(ControlRouting):
    cut = False  # the model's sound jumps at the next block (the sink fades across it)

    def __init__(self, config, ring, status, commands, events):
        from studyapp.model.loop import ClosedLoop, LoopConfig

        self.config = config
        self.ring = ring
        self.status = status
        self.commands = commands
        self.events = events
        self.stopping = False
        self.midi = None
        self.sink = None
        status.set(state="starting", rate=config.rate)
        status.publish()
        sys.setswitchinterval(0.0005)  # PortAudio's callback thread needs the GIL promptly

        self.sink = open_sink(config.audio, config.rate, lead=config.lead,
                              say=lambda text: self.notice(text, "warning", "audio"))
        self.recordings = Recordings(self.sink, self.notice)  # the session's recordings of what is heard
        loop_config = LoopConfig(
            rate=config.rate, estimators=config.estimators, source=config.source, fmax=1.0,
            gesture=config.gesture, seed=config.seed, audio=self.sink.render,
        )
        if config.f0 is not None:
            loop_config.f0 = config.f0
        self.loop = ClosedLoop(loop_config, device=make_device(config))
        self.link = DeviceLink.of(self.loop.device, self.events, self.notice)  # a device that owns the clock
        self.safety = Safety(self.loop, config.safety)
        self.loop.set_fmax(self.safety.clamp_fmax(config.fmax))
        self.loop.set_bowing(config.bowing)  # a session's engine starts silent, before its first step
        self.channels = channels_for(self.loop.names)
        if self.channels != ring.channels:
            raise RuntimeError(f"telemetry channels {self.channels} differ from the ring's {ring.channels}")
        self.cmap = ControlMap.from_protocol(config.midi_map) if config.midi_map else ControlMap.lpd8()
        self.init_controls(as_actions(config.actions) if config.actions is not None
                           else cmd.default_actions(config.sources()))
        self.midi = open_input(config.midi, say=lambda text: self.notice(text, "warning", "midi"))
        self.block = config.block_size()
        self.period = self.block / self.loop.rate
        self.realtime = _try_realtime() if config.realtime else False
        self.k = 0
        self.trial_start = 0.0  # loop time (s) of the last ResetString
        self.pacing = None  # the run's block clock and its counts (pacing.py), from run() on
        self._rows = Rows(self.channels, self.block)
        self._faults_seen = 0
        self.guard = GuardWatch(status, config.guard_timeout)  # the force guard's watch (supervision.py)
        status.set(
            block=self.block, fmax=self.loop.fmax, force_scale=1.0, source=self.loop.source,
            audio=self.sink.description, midi=self.midi.description if self.midi else "none",
            audio_paced=self.sink.paced,
        )

    # messages to the parent ---------------------------------------------------
    def notice(self, text, level="info", topic=""):
        self.events.put(ev.Notice(text, level, topic))

    def fault(self, text):
        self.status.set(faults=self.status.get("faults") + 1, fault=text)
        self.events.put(ev.Fault(text, time.monotonic()))

    # commands: one handler per command type ------------------------------------
    def _source(self, c):
        before = self.loop.source
        self.loop.set_source(c.name)
        self.cut = self.cut or self.loop.source != before
        self.status.set(source=self.loop.source)

    def _fmax(self, c):
        self.loop.set_fmax(self.safety.clamp_fmax(c.newtons))

    def _reset_string(self, c):
        self.loop.reset_string()
        self.cut = True
        if self.link is not None:
            self.link.trial_started(self.trial)
        self.trial_start = self.k * self.block / self.loop.rate

    def _bowing(self, c):
        if bool(c.on) != self.loop.bowing:
            self.recordings.cue(None, None, None, "bow_on" if c.on else "bow_off")
        self.loop.set_bowing(bool(c.on))

    def _clear_fault(self, c):
        if self.loop.fault and not (self.link is not None and self.link.device.fault is not None):
            self.notice(f"cannot clear: the loop itself latched '{self.loop.fault}'; restart the engine", "warning")
        elif self.link is None or self.link.clear(self.loop):
            self.safety.clear()
            self.status.set(fault="")

    def _stop(self, c):
        self.stopping = True

    def _midi_port(self, c):
        if self.midi is not None and self.midi.inlet is not None:
            self.notice(self.midi.connected(c.name), "info", "midi")
            self.status.set(midi=self.midi.description)

    HANDLERS = {
        cmd.SetSource: _source,
        cmd.SetFmax: _fmax,
        cmd.SetHandTarget: lambda self, c: self.loop.set_hand_target(c.metres),
        cmd.SetBowing: _bowing,
        cmd.SetGesture: lambda self, c: self.loop.set_gesture(c.name),
        cmd.ResetString: _reset_string,
        cmd.SetVolume: lambda self, c: self.sink.set_volume(float(c.gain)),
        cmd.SetMute: lambda self, c: self.sink.set_mute(bool(c.on)),
        cmd.Learn: lambda self, c: self.cmap.learn(c.control),
        cmd.ClearFault: _clear_fault,
        cmd.Stall: lambda self, c: time.sleep(float(c.seconds)),
        cmd.Stop: _stop,
        cmd.ReferenceTone: lambda self, c: self.sink.set_reference_tone(c.hz, c.level_dbfs),
        cmd.RecordAudio: lambda self, c: self.recordings.record(c.path, c.mode),
        cmd.AudioCue: lambda self, c: self.recordings.cue(c.step, c.task, c.trial, c.event),
        cmd.InstallActions: ControlRouting.install,
        cmd.MidiPort: _midi_port,
        cmd.Control: lambda self, c: self.control(c.control, c.value, c.sent, self.k, "screen"),
    }

    def apply(self, command):
        """Apply one command; returns its command-to-effect latency (s), or None if it was refused."""
        try:
            self.HANDLERS[type(command)](self, command)
        except (ValueError, TypeError) as exc:
            self.notice(f"command {command!r} ignored: {exc}", "warning")
            return None
        # measured when applied, just before the block it affects: a message that arrived after
        # the block's start time was taken but before the drain would otherwise read negative
        latency = time.monotonic() - command.sent
        self.status.set(command_latency=latency,
                        command_latency_max=max(self.status.get("command_latency_max"), latency))
        return latency

    def drain(self):
        while True:
            try:
                command = self.commands.get_nowait()
            except queue.Empty:
                break
            except (EOFError, OSError):
                self.stopping = True
                break
            self.apply(command)
        if self.midi is not None:
            self.take_midi()

    # the loop -------------------------------------------------------------
    def prime(self):
        """Run the first blocks before any clock starts: compiled code loads, a paced sink's FIFO fills."""
        for _ in range(2):
            self.step(time.monotonic())
        while self.sink.paced and self.sink.level < self.sink.lead_frames:
            self.step(time.monotonic())
        # A full collection over the ~150 000 objects numpy, numba and scipy leave behind takes
        # ~0.2 s, holding the GIL: long enough to trip the watchdog and starve the audio callback.
        # Collect once now, before any clock runs, and freeze the survivors out of the collector.
        gc.collect()
        gc.freeze()
        self.sink.start()

    def step(self, started):
        """One block; returns (finished, wall-clock compute, CPU time of this thread)."""
        cpu_started = time.thread_time()
        enabled, why = self.guard.force()
        self.safety.before_block(enabled, why=why)
        if self.link is not None:
            self.link.before_block(enabled, self.status.force_off_reason, self.safety.latched)
        bowing = self.loop.bowing
        out = self.loop.run(self.block)
        if self.sink.render:
            # the bow as it was for this block (a fault lifts it): silence while it is off the string
            self.sink.push(out["audio"], sounding=bowing and self.loop.fault is None, cut=self.cut)
        self.cut = False
        self.ring.stage(self._rows.fill(out, self.loop, self.trial, self.trial_start))
        # Read the word after staging, just before the commit: a trip before this read withholds the
        # block's force here; one after it finds the block staged, and the guard withholds it (guard.py).
        enabled, why = self.guard.force()
        self.safety.check(out, force_enable=enabled, why=why)
        if not enabled:
            self.ring.withhold(WITHHELD)
        self.ring.commit()
        finished = time.monotonic()
        cpu = time.thread_time() - cpu_started
        self.k += 1
        if self.midi is not None:
            self.midi.new_block(self.k, finished)
        return finished, finished - started, cpu

    def run(self):
        status = self.status
        self.prime()
        self.guard.wait()
        status.set(state="running", heartbeat=time.monotonic())
        status.publish(texts=True)
        # from here the loop sees the parent gone within 50 ms and stops cleanly; handed over before Ready,
        # after which the thread that started this process may end (parent_death.py)
        parent_death.watched()
        self.events.put(ev.Ready({
            "rate": self.loop.rate, "block": self.block, "names": list(self.loop.names),
            "audio": self.sink.description, "midi": self.midi.description if self.midi else "none",
            "midi_inlet": self.midi.inlet if self.midi else None, "realtime": self.realtime,
            "paced": "device" if self.link is not None else "audio" if self.sink.paced else "timer",
            "device": self.link.info if self.link is not None else None,
        }))
        parent = multiprocessing.parent_process()
        pacing = self.pacing = Pacing(self.sink, self.period, self.k, self.loop.device)
        if self.link is not None:
            self.link.started()  # fresh frames, ARM: the device's watchdog runs from here
        next_parent_check = pacing.start
        while not self.stopping:
            if pacing.wait(self.k):
                status.set(audio_paced=False)
                self.notice(f"{'device: it faulted' if self.link else 'audio: the device stopped calling back'}; "
                            f"{TIMER_TAKES_OVER}", "warning", "device" if self.link else "audio")
            started = time.monotonic()
            self.drain()
            if self.stopping:
                break
            deadline = pacing.deadline(self.k)
            finished, compute, cpu = self.step(started)
            if pacing.missed(deadline, finished, compute, cpu):
                status.set(deadline_misses=status.get("deadline_misses") + 1)
            new_faults = self.safety.faults[self._faults_seen:]
            for text in new_faults:
                self.fault(text)
            self._faults_seen += len(new_faults)
            if self.link is not None and self.config.device_rearm and self.link.rearm_after_trip(self.loop):
                self.safety.clear()  # live: a watchdog trip is re-armed at once (engine/device_link.py)
                self.status.set(fault="")
            status.set(
                heartbeat=finished, blocks=self.k, samples=self.k * self.block, load=pacing.loads[-1],
                audio_underruns=self.sink.underruns, audio_xruns=self.sink.xruns, audio_limited=self.sink.limited,
                fault_latched=self.safety.latched is not None, fmax=self.loop.fmax,
                force_scale=self.loop.force_scale, **(self.link.status() if self.link is not None else {}),
            )
            status.set(**pacing.window(finished, self.block))
            status.publish(texts=self._texts_changed())
            if finished >= next_parent_check:
                next_parent_check = finished + 0.05
                if parent is not None and not parent.is_alive():
                    self.stopping = True
        pacing.end = time.monotonic()
        status.set(state="stopping", heartbeat=pacing.end)
        status.publish()

    def _texts_changed(self):
        texts = self.status.texts
        if getattr(self, "_last_texts", None) != texts:
            self._last_texts = dict(texts)
            return True
        return False

    def summary(self):
        s = self.status
        pacing = self.pacing
        t = pacing.summary(self.k, self.block, pacing.end or time.monotonic()) if pacing else IDLE
        return {
            "rate": self.loop.rate, "blocks": self.k, "samples": self.k * self.block,
            "seconds": t["seconds"], "achieved_rate": t["achieved_rate"], "deadline_misses": int(s.get("deadline_misses")),
            "audio_underruns": self.sink.underruns, "audio_xruns": self.sink.xruns,
            "audio_limited": self.sink.limited, "audio_frames": self.sink.frames_played, "faults": list(self.safety.faults[:SUMMARY_FAULTS]),
            "faults_total": len(self.safety.faults), "midi_messages": int(s.get("midi_messages")),
            "midi_overflows": self.midi.overflows if self.midi else 0,
            "command_latency_max": float(s.get("command_latency_max")),
            "load_mean": t["load_mean"], "load_p99": t["load_p99"], "load_max": t["load_max"], "realtime": self.realtime,
            "block": self.block, "paced": pacing.clock if pacing else "audio" if self.sink.paced else "timer",
            "wake_late_max": t["wake_late_max"], "overruns": t["overruns"], "stalls": t["stalls"],
            "audio_recordings": self.recordings.summary(),
            **(self.link.summary() if self.link is not None else {}),
        }

    def close(self):
        """Release the devices and report; ``True`` if the process must leave by ``os._exit``."""
        stuck = False
        self.recordings.close()
        if self.sink is not None:
            self.sink.close()
            stuck = getattr(self.sink, "stuck", False)
            if stuck:
                self.notice("audio: the device did not release its stream (JACK dropped the client?); "
                            "leaving it open", "warning", "audio")
        if self.midi is not None:
            self.midi.close()
        if getattr(self, "link", None) is not None:
            self.link.close()
        if getattr(self, "loop", None) is not None:
            self.events.put(ev.Stopped(self.summary()))
            self.status.set(state="stopped", heartbeat=time.monotonic())
            self.status.publish(texts=True)
        sounddevice = sys.modules.get("sounddevice")
        if sounddevice is not None and not stuck:
            # PortAudio must let go of JACK now: a JACK server stopping first would abort us at exit
            sounddevice._terminate()
        return stuck


def _try_realtime():
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(REALTIME_PRIORITY))
    except (OSError, AttributeError):
        return False
    return True
