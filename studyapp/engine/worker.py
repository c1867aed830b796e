"""The worker process: the closed loop in real time, block by block.

Started by ``engine.Engine`` with the spawn context (a fresh interpreter: no
inherited locks, threads or Qt state). It builds only what the scene names:
the loop with the active estimators, the audio sink (no audio rendered for a
null sink), the MIDI input if asked for. Then, for block k of B samples at
rate R (period T = B / R):

1. wait for the pacing clock: the audio device's FIFO dropping below its lead
   (the device callback is the clock), or else the monotonic timer reaching
   t0 + k T;
2. apply every queued command and MIDI control (block boundary), measuring
   the command-to-effect latency: from the command's ``sent`` time (or the
   MIDI message's arrival) to its application, just before this block runs;
3. run the loop for B samples; let the safety layer inspect them;
4. push the audio to the sink, the telemetry to the ring, the status record.

The sink's signal chain (engine/signal_chain.py) is told, with each block,
whether the bow is on the string (silence while it is lifted) and whether the
model's sound jumps at this block (``cut``: a string reset at a trial's start,
a change of velocity source), so that every start, stop and cut fades.

A block is a *deadline miss* when it finishes after its deadline: t0 + (k+1) T
on the timer; on the audio clock, when the device had to play silence while
the block was being made. The load of a block is its compute time (wall
clock) over T. A miss is an *overrun* when the block's own compute took longer
than T on the CPU (the thread's CPU time), a *stall* when it took longer than
T by the wall clock only (the worker was taken off the CPU mid-block); the
other misses come from starting late (the OS woke the worker late, or an
earlier block overran): the summary's ``wake_late_max`` says how late.
Stalls and late starts are the machine's share of the misses, overruns the
engine's.

Besides the loop's signals, each block publishes what a study session needs
(push, not pull): the friction (the string's normalised force, paper eq. 2),
the loop's stability monitor's verdict (``broken``, 0 or 1) and ``score``
(model/stability.py: the one judgement of breakdown), the tag of the mapping
in force (``trial``) and the trial clock (seconds since the last
``ResetString``, which starts a trial). Knob and pad actions are applied here,
in and out of a session, through the mapping installed last
(``commands.InstallActions``); on-screen controls arrive as ``Control``
commands and take the same route as MIDI. A physical (MIDI) knob that sets a
level acts only once it has passed through the level in force (soft takeover,
``engine/pickup.py``): until then it is reported with ``pending_pickup`` and
changes nothing, so a knob left high never jumps F_max at a trial start or
after a pause. On-screen knobs show the level itself and need no pickup.

A MIDI input waiting for its controller (JACK hot-plug, ``midi.py``) is
connected by the parent; a ``MidiPort`` command names the port (or says it
went away), and the status block's ``midi`` text and a notice follow.

The worker stops on a ``Stop`` command, or when its parent dies (it checks the
parent's sentinel every 50 ms, so no orphan keeps running).

It runs its loop only under the force guard's watch (engine/guard.py): it
waits for the guard's first heartbeat before it reports ready, and from then
on switches its force off itself (reason "guard") when that heartbeat is older
than ``guard_timeout``: a guard that died or was stopped leaves no force unwatched.
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

import numpy as np

from studyapp.engine import commands as cmd
from studyapp.engine import events as ev
from studyapp.engine.audio import open_sink
from studyapp.engine.audio_recorder import AudioRecorder
from studyapp.engine.event_ring import EventRing
from studyapp.engine.midi import ControlMap, coalesce, open_input
from studyapp.engine.pickup import LEVEL_ACTIONS, level_position, passes_through
from studyapp.engine.ring import Ring
from studyapp.engine.safety import Safety, force_off_text
from studyapp.engine.status import StatusBlock
from studyapp.model.fmax_knob import KNOB_MAX

# telemetry channels before the estimates ("estimate:NAME")
CHANNELS = (
    "t", "position", "velocity_lvt", "velocity_true", "source_velocity", "string_velocity",
    "force", "fmax", "force_scale", "friction", "broken", "stability_score", "trial", "trial_clock",
)
# rows with one value per block, and the rest, copied from the loop's output
_FMAX, _FORCE_SCALE, _BROKEN, _SCORE, _TRIAL, _CLOCK = (
    CHANNELS.index(c) for c in ("fmax", "force_scale", "broken", "stability_score", "trial", "trial_clock"))
_SAMPLED = tuple((i, c) for i, c in enumerate(CHANNELS)
                 if i not in (_FMAX, _FORCE_SCALE, _BROKEN, _SCORE, _TRIAL, _CLOCK))
REALTIME_PRIORITY = 5  # below JACK's own threads (10 and 9 by default)
RESYNC = 0.1  # s behind the timer after which the schedule restarts from now


def channels_for(names):
    return CHANNELS + tuple(f"estimate:{n}" for n in names)


def make_device(spec, rate):
    """A real device driver from ``"module:factory"`` (called with the rate), or ``None``."""
    if not spec:
        return None
    module, _, factory = spec.partition(":")
    return getattr(importlib.import_module(module), factory)(rate)


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


class Worker:
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
        self.recorder = None  # the session's recording of what is heard (RecordAudio)
        self.recordings = []  # every recorder of this run: closed, with what it wrote, in close()
        status.set(state="starting", rate=config.rate)
        status.publish()
        sys.setswitchinterval(0.0005)  # PortAudio's callback thread needs the GIL promptly

        self.sink = open_sink(config.audio, config.rate, lead=config.lead,
                              say=lambda text: self.notice(text, "warning", "audio"))
        loop_config = LoopConfig(
            rate=config.rate, estimators=config.estimators, source=config.source, fmax=1.0,
            gesture=config.gesture, seed=config.seed, audio=self.sink.render,
        )
        if config.f0 is not None:
            loop_config.f0 = config.f0
        self.loop = ClosedLoop(loop_config, device=make_device(config.device, config.rate))
        self.safety = Safety(self.loop, config.safety)
        self.loop.set_fmax(self.safety.clamp_fmax(config.fmax))
        self.loop.set_bowing(config.bowing)  # a session's engine starts silent, before its first step
        self.channels = channels_for(self.loop.names)
        if self.channels != ring.channels:
            raise RuntimeError(f"telemetry channels {self.channels} differ from the ring's {ring.channels}")
        self.cmap = ControlMap.from_protocol(config.midi_map) if config.midi_map else ControlMap.lpd8()
        self.actions = config.actions if config.actions is not None else cmd.default_actions(config.sources())
        self.midi = open_input(config.midi, say=lambda text: self.notice(text, "warning", "midi"))
        self.block = config.block_size()
        self.period = self.block / self.loop.rate
        self.realtime = _try_realtime() if config.realtime else False
        self.k = 0
        self.trial = 0  # the tag of the mapping in force
        self.trial_start = 0.0  # loop time (s) of the last ResetString
        self.knob_seen = {}  # each MIDI control's last position (0..127), whatever the mapping: for pickup
        self.ratings = {}  # each rating knob's position, the level its "select" action sets
        self.loads = []  # every timed block's load, for the summary's percentiles
        self.wake_late_max = 0.0  # the timer's worst wake-up delay: the OS's share of a miss
        self.overruns = 0  # misses whose block alone took longer than its period on the CPU
        self.stalls = 0  # misses whose block took longer than its period by the wall clock only
        self._rows = np.empty((len(self.channels), self.block))
        self._faults_seen = 0
        self.supervised = False  # the guard's heartbeat is checked from the first timed block on (run)
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
        self.trial_start = self.k * self.block / self.loop.rate

    def _bowing(self, c):
        if bool(c.on) != self.loop.bowing and self.recorder is not None:
            self.recorder.cue(None, None, None, "bow_on" if c.on else "bow_off", at=self.sink.next_frame())
        self.loop.set_bowing(bool(c.on))

    def _clear_fault(self, c):
        if self.loop.fault:
            self.notice(f"cannot clear: the loop itself latched '{self.loop.fault}'; restart the engine", "warning")
        else:
            self.safety.clear()
            self.status.set(fault="")

    def _install(self, c):
        self.actions = dict(c.actions)
        self.trial = int(c.trial)
        if c.positions is not None:
            self.ratings = dict(c.positions)

    def _stop(self, c):
        self.stopping = True

    def _midi_port(self, c):
        if self.midi is not None and self.midi.inlet is not None:
            self.notice(self.midi.connected(c.name), "info", "midi")
            self.status.set(midi=self.midi.description)

    def _record(self, c):
        """Stop the recording in progress (its writer finishes on its own), then start one at ``c.path``."""
        if self.recorder is not None:
            self.recorder.stop()
            self.sink.recorder = self.recorder = None
        if c.path is None:
            return
        if not self.sink.render:
            self.notice(f"audio: the {self.sink.description} sink renders no audio: nothing to record", "warning", "audio")
            return
        self.recorder = self.sink.recorder = AudioRecorder(c.path, self.sink.rate, c.mode)
        self.recordings.append(self.recorder)
        self.notice(f"audio: recording what is heard to {self.recorder.path}", "info", "audio")

    def _cue(self, c):
        if self.recorder is not None:
            self.recorder.cue(c.step, c.task, c.trial, c.event, at=self.sink.next_frame())

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
        cmd.RecordAudio: _record,
        cmd.AudioCue: _cue,
        cmd.InstallActions: _install,
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

    def control(self, control, value, arrived, block, origin="midi"):
        """A control moved (MIDI, or on screen): apply its action, tell the parent."""
        action = self.actions.get(control)
        step = round(value * KNOB_MAX)
        target = self._pickup_target(control, action, step) if origin == "midi" else None
        commands = cmd.action_commands(action, value, arrived) if action and target is None else ()
        latency = None
        for command in commands:
            latency = self.apply(command)
        if commands and action[0] == "select":
            self.ratings[control] = step
        self.events.put(ev.Applied(control, value, arrived, latency, self.k - block, self.k, self.trial,
                                   commands, origin, pending_pickup=target is not None,
                                   pickup_target=None if target is None else target / KNOB_MAX))

    def _pickup_target(self, control, action, step):
        """The knob step a physical knob must pass through before it acts; None when it acts now."""
        previous, self.knob_seen[control] = self.knob_seen.get(control), step
        if not action or action[0] not in LEVEL_ACTIONS:
            return None
        volume = self.sink.gain.volume if action[0] == "volume" else None
        target = level_position(action, self.loop.fmax, volume, self.ratings.get(control))
        if target is None or passes_through(target, previous, step):
            return None
        return target

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
        if self.midi is None:
            return
        received = self.midi.poll()
        self.status.set(midi_messages=self.midi.received)
        for msg, arrived, block in coalesce(received):
            learning = self.cmap.learning
            hit = self.cmap.lookup(msg)
            if hit is None:
                continue
            control, value = hit
            if learning is not None and self.cmap.learning is None:
                self.events.put(ev.Learned(control, self.cmap.to_dict()[control]))
            self.control(control, value, arrived, block)

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
        enabled = self._force_enabled()
        self.safety.before_block(enabled, why=None if enabled else self._force_off_text())
        bowing = self.loop.bowing
        out = self.loop.run(self.block)
        enabled = self._force_enabled()
        self.safety.check(out, force_enable=enabled, why=None if enabled else self._force_off_text())
        if self.sink.render:
            # the bow as it was for this block (a fault lifts it): silence while it is off the string
            self.sink.push(out["audio"], sounding=bowing and self.loop.fault is None, cut=self.cut)
        self.cut = False
        rows = self._rows
        for i, name in _SAMPLED:
            rows[i] = out[name]
        monitor = self.loop.monitor
        rows[_FMAX] = self.loop.fmax
        rows[_FORCE_SCALE] = self.loop.force_scale
        rows[_BROKEN] = monitor.broken
        rows[_SCORE] = monitor.score
        rows[_TRIAL] = self.trial
        np.subtract(out["t"], self.trial_start, out=rows[_CLOCK])
        rows[len(CHANNELS):] = out["estimates"]
        self.ring.write(rows)
        finished = time.monotonic()
        cpu = time.thread_time() - cpu_started
        self.k += 1
        if self.midi is not None:
            self.midi.new_block(self.k, finished)
        return finished, finished - started, cpu

    def _force_enabled(self):
        """The parent's ``force_enable`` word, cleared here first if the force guard has gone silent."""
        status = self.status
        if self.supervised and status.force_enable:
            silence = time.monotonic() - status.guard_heartbeat
            if silence > self.config.guard_timeout:
                status.disable_force("guard", silence)
        return status.force_enable

    def wait_for_guard(self, timeout=60.0):
        """Block until the force guard has started watching (``RuntimeError`` after ``timeout`` s)."""
        end = time.monotonic() + timeout
        while time.monotonic() - self.status.guard_heartbeat > self.config.guard_timeout:
            if time.monotonic() > end:
                raise RuntimeError(f"the force guard did not start within {timeout:g} s")
            time.sleep(0.005)
        self.supervised = True

    def _force_off_text(self):
        """Why the parent cleared ``force_enable``, in words (read only while it is cleared)."""
        return force_off_text(self.status.force_off_reason, self.status.force_off_silence)

    def run(self):
        status = self.status
        self.prime()
        self.wait_for_guard()
        status.set(state="running", heartbeat=time.monotonic())
        status.publish(texts=True)
        self.events.put(ev.Ready({
            "rate": self.loop.rate, "block": self.block, "names": list(self.loop.names),
            "audio": self.sink.description, "midi": self.midi.description if self.midi else "none",
            "midi_inlet": self.midi.inlet if self.midi else None, "realtime": self.realtime, "paced": "audio" if self.sink.paced else "timer",
        }))
        parent = multiprocessing.parent_process()
        audio_clock = self.sink.paced
        silent_waits = 0
        t0 = self.run_start = time.monotonic()
        k0 = self.run_k0 = self.k
        window_start, window_samples = t0, 0
        loads = []
        shortfalls = self.sink.shortfalls
        next_parent_check = t0
        while not self.stopping:
            if audio_clock:
                silent_waits = 0 if self.sink.wait(0.05) else silent_waits + 1
                if silent_waits >= 3:
                    audio_clock = False
                    t0, k0 = time.monotonic(), self.k
                    status.set(audio_paced=False)
                    self.notice("audio: the device stopped calling back; the timer paces the loop now", "warning", "audio")
            else:
                start_at = t0 + (self.k - k0) * self.period
                now = time.monotonic()
                if start_at > now:
                    time.sleep(start_at - now)
                    self.wake_late_max = max(self.wake_late_max, time.monotonic() - start_at)
                elif now - start_at > RESYNC:
                    t0, k0 = now, self.k
            started = time.monotonic()
            self.drain()
            if self.stopping:
                break
            deadline = t0 + (self.k - k0 + 1) * self.period
            finished, compute, cpu = self.step(started)
            load = compute / self.period
            loads.append(load)
            self.loads.append(load)
            late = self.sink.shortfalls > shortfalls if audio_clock else finished > deadline
            shortfalls = self.sink.shortfalls
            if late:
                status.set(deadline_misses=status.get("deadline_misses") + 1)
                if cpu > self.period:
                    self.overruns += 1
                elif compute > self.period:
                    self.stalls += 1
            new_faults = self.safety.faults[self._faults_seen:]
            for text in new_faults:
                self.fault(text)
            self._faults_seen += len(new_faults)
            status.set(
                heartbeat=finished, blocks=self.k, samples=self.k * self.block, load=load,
                audio_underruns=self.sink.underruns, audio_xruns=self.sink.xruns,
                fault_latched=self.safety.latched is not None, fmax=self.loop.fmax,
                force_scale=self.loop.force_scale,
            )
            window_samples += self.block
            if finished - window_start >= 1.0:
                status.set(achieved_rate=window_samples / (finished - window_start),
                           load_mean=float(np.mean(loads)), load_max=float(np.max(loads)))
                window_start, window_samples, loads = finished, 0, []
            status.publish(texts=self._texts_changed())
            if finished >= next_parent_check:
                next_parent_check = finished + 0.05
                if parent is not None and not parent.is_alive():
                    self.stopping = True
        self.run_end = time.monotonic()
        status.set(state="stopping", heartbeat=self.run_end)
        status.publish()

    def _texts_changed(self):
        texts = self.status.texts
        if getattr(self, "_last_texts", None) != texts:
            self._last_texts = dict(texts)
            return True
        return False

    def summary(self):
        s = self.status
        start = getattr(self, "run_start", None)
        end = getattr(self, "run_end", None) or time.monotonic()
        achieved = (self.k - self.run_k0) * self.block / (end - start) if start and end > start else 0.0
        return {
            "rate": self.loop.rate, "blocks": self.k, "samples": self.k * self.block,
            "seconds": end - start if start else 0.0, "achieved_rate": achieved, "deadline_misses": int(s.get("deadline_misses")),
            "audio_underruns": self.sink.underruns, "audio_xruns": self.sink.xruns,
            "audio_frames": self.sink.frames_played, "faults": list(self.safety.faults), "midi_messages": int(s.get("midi_messages")),
            "midi_overflows": self.midi.overflows if self.midi else 0,
            "command_latency_max": float(s.get("command_latency_max")),
            "load_mean": float(np.mean(self.loads)) if self.loads else 0.0,
            "load_p99": float(np.percentile(self.loads, 99)) if self.loads else 0.0,
            "load_max": float(np.max(self.loads)) if self.loads else 0.0, "realtime": self.realtime,
            "block": self.block, "paced": "audio" if self.sink.paced else "timer",
            "wake_late_max": self.wake_late_max, "overruns": self.overruns, "stalls": self.stalls,
            "audio_recordings": [{"file": str(r.path), "frames": r.frames, "dropped": r.dropped, "error": r.error}
                                 for r in self.recordings],
        }

    def _close_recordings(self, timeout=5.0):
        """Let every recording's writer finish; say what one could not write."""
        if self.recorder is not None:
            self.recorder.stop()
            self.sink.recorder = self.recorder = None  # the sink's flush on close is not the session's
        for recorder in self.recordings:
            if not recorder.join(timeout):
                self.notice(f"audio: {recorder.path}: the writer did not finish within {timeout:g} s", "warning", "audio")
            if recorder.error:
                self.notice(f"audio: recording stopped: {recorder.error}", "warning", "audio")
            if recorder.dropped:
                self.notice(f"audio: {recorder.path}: {recorder.dropped} frames dropped (the disk fell behind), "
                            "written as silence", "warning", "audio")

    def close(self):
        """Release the devices and report; ``True`` if the process must leave by ``os._exit``."""
        stuck = False
        self._close_recordings()
        if self.sink is not None:
            self.sink.close()
            stuck = getattr(self.sink, "stuck", False)
            if stuck:
                self.notice("audio: the device did not release its stream (JACK dropped the client?); "
                            "leaving it open", "warning", "audio")
        if self.midi is not None:
            self.midi.close()
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
