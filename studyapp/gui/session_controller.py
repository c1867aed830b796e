"""The console's model: one study session driven through the real-time engine. No Qt.

The study logic lives in ``studyapp.experiment``: ``Session`` (the folder,
schedule and crash-safe log) and ``SessionRunner`` (the tasks as state
machines, everything logged). This controller only connects them to the
engine and to whoever plays (a person with MIDI or on-screen knobs, or the
simulated participant), and announces what changes through ``events``
(``evented.EventGroup``) for the views to show.

Time. The GUI thread calls ``poll()`` from a timer. Each call copies the
telemetry written since the previous one from the engine's shared-memory ring
(never waiting), shows it (``telemetry`` event) and, while a trial runs, feeds
it to the trial's ``EngineLoop`` and calls ``runner.advance(n / rate)``: the
task's clock, the stability verdict and the logged events follow the samples
the engine really ran.

Engines. A protocol gets a *preview* engine with every condition it names:
outside a session the knobs act live as on the bare engine (knob 1 F_max on
its logarithmic scale, knob 2 volume, pad i the i-th condition;
``studyapp.engine.commands.default_actions``), so the experimenter can check
device, sound and scope. Starting a session starts a fresh engine seeded with
the session's seed; once the session ends it stays as the preview engine.

States (``state``): ``idle`` (no session), ``starting`` (session folder made,
engine starting), ``running``, ``paused``, ``finished``, ``aborted``. Pause
holds the loop (F_max 0, bow lifted), stops the task's clock and ignores the
participant's controls; resume gives the settings back.

Emergency stop: at once, the engine's ``force_enable`` word in shared memory
is cleared (the worker latches a fault and zeroes its force scale at its next
block, ``studyapp.engine.safety``), F_max is set to 0 and the bow lifted; a
running session pauses. ``resume`` clears the fault and, once the engine
reports it cleared, starts the current trial again from its beginning (as a
resumed session does: an adjustment trial from F_max = 0), never back at the
F_max that was in force.

Engine failure: if the worker dies or hangs during a session (its watchdog
zeroes the force), the session pauses and says so; ``resume`` starts a new
engine and, once it runs, the current trial again from its beginning.
"""

import time

from studyapp.engine.commands import action_command, default_actions
from studyapp.engine.config import EngineConfig
from studyapp.errors import UserError
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.session import Session, check_participant
from studyapp.experiment.session_runner import SessionRunner
from studyapp.gui.engine_host import EngineHost
from studyapp.gui.engine_loop import EngineLoop
from studyapp.gui.evented import EventGroup

STATUS_PERIOD = 0.25  # s between status events (the status bar needs no more)
ACTIVE = ("starting", "running", "paused")
GESTURES = ("strokes", "hold", "live")  # what the console offers: scripted strokes, a held handle, the mouse


def scene_conditions(protocol):
    """Every condition the protocol names, in the order it first names them."""
    names = []
    for task in protocol.tasks:
        for name in protocol.task(task).conditions:
            if name not in names:
                names.append(name)
    return names


def instructions_for(protocol, task):
    return protocol.task(task).instructions.strip()


class SessionController:
    def __init__(self, audio="device", midi="first", device=None, realtime=True, hang_timeout=None,
                 clock=time.monotonic):
        self.audio = audio
        self.midi = midi
        self.device = device
        self.realtime = realtime
        self.hang_timeout = hang_timeout
        self.clock = clock
        self.events = EventGroup("protocol", "engine", "state", "trial", "knob", "selection", "bowing", "gesture",
                                 "telemetry", "status", "message", "response")
        self.protocol = None
        self.host = None
        self.session = None
        self.runner = None
        self.state = "idle"
        self.emergency = False
        self.clearing = False  # an emergency stop is being cleared
        self.restarting = False  # a new engine is starting after the session's engine failed
        self.engine_lost = False  # the session's engine failed; resume restarts it
        self.fed = 0  # end (sample number) of the telemetry fed to the running trial
        self.trial_serial = 0  # counts trials started (restarts too), for the simulated participant
        self._engine_state = None
        self._next_status = 0.0

    # protocol and engines ------------------------------------------------------
    def load_protocol(self, path):
        """Load and validate ``path`` (``UserError`` if invalid) and start its preview engine."""
        if self.state in ACTIVE:
            raise UserError("a session is in progress: abort it before changing the protocol")
        protocol = load_protocol(path)
        self.protocol = protocol
        self.events.protocol.emit(protocol=protocol)
        self._replace_host(self._engine_config(protocol.seed), f"preview of {protocol.study}")
        return protocol

    def _engine_config(self, seed):
        p = self.protocol
        names = scene_conditions(p)
        config = EngineConfig(rate=p.rate, estimators={n: p.estimator_params(n) for n in names}, source=names[0],
                              fmax=0.0, gesture=p.gesture, seed=int(seed) % 2**32, audio=self.audio, midi=self.midi,
                              actions={}, realtime=self.realtime, device=self.device)
        if self.hang_timeout is not None:
            config.hang_timeout = float(self.hang_timeout)
        return config

    def _replace_host(self, config, describe):
        old, self.host = self.host, EngineHost(config, describe).start()
        if old is not None:
            old.stop(wait=False)
        self.emergency = False
        self.clearing = False
        self._announce_engine()

    @property
    def engine(self):
        """The running engine, or None (starting, failed or stopped)."""
        return self.host.engine if self.host is not None and self.host.running else None

    def _announce_engine(self):
        state = self.host.state if self.host is not None else "stopped"
        if state != self._engine_state:
            self._engine_state = state
            info = self.host.engine.info if state == "running" else {}
            self.events.engine.emit(state=state, info=info, config=self.host.config if self.host else None)
            if state == "running" and self.runner is None:
                self.events.gesture.emit(name=self.protocol.gesture)
                self.events.bowing.emit(on=False)

    # session ------------------------------------------------------------------
    def start_session(self, participant, results="results", resume=False, seed=None, apparatus=None):
        """Open the participant's session (``UserError`` when refused) and start its engine."""
        if self.protocol is None:
            raise UserError("no protocol loaded: choose one first")
        if self.state in ACTIVE:
            raise UserError("a session is already in progress")
        if self.emergency:
            raise UserError("the emergency stop is set: clear it (Resume) before starting a session")
        check_participant(participant)
        if resume:
            session = Session.resume(self.protocol, participant, results, seed=seed)
        else:
            described = {"device": self.device or "simulated", "engine": "real-time", **(apparatus or {})}
            session = Session.create(self.protocol, participant, results, seed=seed, apparatus=described)
        self.session = session
        self.runner = None
        self.engine_lost = False
        self._set_state("starting")
        self._replace_host(self._engine_config(session.seed), f"session {session.folder}")
        self.message(f"session {session.folder}: {len(session.finished_steps())} of "
                     f"{len(session.schedule)} trials done; starting the engine")
        return session

    def _begin(self):
        """The session's engine runs: log the run, then the first unfinished trial."""
        runner = SessionRunner(self.session, make_loop=self._make_loop, progress=self.message)
        self.runner = runner
        runner.begin()
        self._log_engine()
        self._set_state("running")
        self._next_trial()
        if self.emergency:
            # the stop was pressed while the engine was starting: it holds for this engine too
            self.emergency_stop()

    def _log_engine(self):
        info = self.host.engine.info
        self.runner.log({"type": "engine", "rate": info["rate"], "block": info["block"], "audio": info["audio"],
                         "midi": info["midi"], "paced": info["paced"], "realtime": info["realtime"],
                         "seed": self.host.config.seed,
                         "note": "one real-time engine per session: its seed, not the trials' loop_seed, "
                                 "seeds the sensor noise"})
        self.fed = self.host.position

    def _make_loop(self, estimators, source, seed):
        return EngineLoop(self.host.engine, estimators, source, self.protocol.gesture)

    def _next_trial(self):
        """Start the first trial without a response (the same one again after an interruption)."""
        trial = self.runner.start_trial()
        if trial is None:
            self._end("finished")
            return
        self.trial_serial += 1
        task = self.runner.task
        if trial.task == "rating":
            values = {j: task.values[c] for j, c in enumerate(task.conditions) if task.values[c] is not None}
        else:
            values = {task.knob_index: task.value}
        for index in range(self.protocol.knobs):
            self.events.knob.emit(index=index, value=int(values.get(index, 0)))
        self.events.trial.emit(trial=trial, step=trial.step, total=len(self.session.schedule),
                               instructions=instructions_for(self.protocol, trial.task))
        self._announce_selection()
        self.events.gesture.emit(name=self.runner.gesture)
        self.events.bowing.emit(on=self.runner.bowing)

    def _end(self, how):
        if self.runner is not None:
            self.runner.finish("done" if how == "finished" else how)
        if self.session is not None:
            self.session.close()
            self.message(f"session {how}: {self.session.folder}")
        if self.engine is not None:
            self.engine.set_fmax(0.0)
            self.engine.set_bowing(False)
        self.runner = None
        self._set_state(how)
        self.events.bowing.emit(on=False)

    def abort(self):
        """Stop the session now; it can be resumed later (``--resume``)."""
        if self.state == "starting":
            self.session.close()
            self.message(f"session aborted before it began: {self.session.folder}")
            self._set_state("aborted")
        elif self.state in ("running", "paused"):
            self.runner.log({"type": "abort"})
            self._end("aborted")

    def pause(self):
        if self.state == "running":
            self.runner.loop.hold(True)
            self.runner.log({"type": "pause"})
            self._set_state("paused")

    def resume(self):
        """Resume a pause; clear an emergency stop; or restart a failed engine (module docstring)."""
        if self.emergency:
            engine = self.engine
            if engine is not None:
                engine.status_block.force_enable = True
                engine.clear_fault()
            self.emergency = False
            self.clearing = engine is not None
            self.message("emergency stop cleared by the experimenter")
            if self.runner is not None:
                self.runner.log({"type": "emergency_clear"})
            self._set_state(self.state)
        elif self.engine_lost and self.state == "paused":
            self.engine_lost = False
            self.restarting = True
            self._replace_host(self.host.config, self.host.describe)
            self.message("starting a new engine; the trial starts again once it runs")
            self._set_state(self.state)
        elif self.state == "paused" and not self.clearing and not self.restarting:
            self.runner.log({"type": "resume"})
            self.runner.loop.hold(False)
            self._set_state("running")

    def emergency_stop(self):
        """Zero the force now (shared-memory word, then F_max 0 and the bow lifted); pause the session."""
        engine = self.engine
        if engine is not None:
            engine.status_block.force_enable = False
            engine.set_fmax(0.0)
            engine.set_bowing(False)
        self.emergency = True
        self.clearing = False
        if self.state in ("running", "paused") and self.runner.loop is not None:
            self.runner.loop.hold(True)
            self.runner.log({"type": "emergency_stop"})
            self.state = "paused"
        self.message("EMERGENCY STOP: force zeroed; press Resume to clear it", level="fault")
        self._set_state(self.state)
        self.events.bowing.emit(on=False)

    def _restart_trial(self):
        self.runner.log({"type": "resume"})
        self._set_state("running")
        self._next_trial()

    def _set_state(self, state):
        self.state = state
        self.events.state.emit(state=state, emergency=self.emergency)

    # the participant's controls --------------------------------------------------
    @property
    def playing(self):
        """True while a trial takes the participant's actions (running, no stop being cleared, engine up)."""
        return (self.state == "running" and not self.emergency and not self.clearing and not self.restarting
                and self.engine is not None)

    @property
    def accepting(self):
        """True when knobs, pads and the bow act: a trial is playing, or live use outside a session."""
        live = self.state in ("idle", "finished", "aborted") and self.engine is not None and not self.emergency
        return self.playing or live

    def knob(self, index, value):
        """Knob ``index`` (from 0) moved to ``value`` (0..127), from the screen or MIDI."""
        value = int(value)
        if not self.accepting:
            return
        self.events.knob.emit(index=index, value=value)
        if self.playing:
            self._handle(self.runner.knob(index, value))
        else:
            self._live(f"knob{index + 1}", value / 127)

    def pad(self, index):
        """Pad ``index`` (from 0) pressed."""
        if not self.accepting:
            return
        if self.playing:
            self._handle(self.runner.pad(index))
        else:
            self._live(f"pad{index + 1}", 1.0)

    def _handle(self, records):
        for record in records:
            if record.get("type") == "pad" and record.get("accepted") is False:
                self.message(f"confirm refused: {record['reason']}")
            if record.get("type") == "response":
                self.events.response.emit(response=record, step=self.runner.trial.step)
        self._announce_selection()
        if self.runner.task is not None and self.runner.task.done:
            self._next_trial()

    def _live(self, control, value):
        action = default_actions(scene_conditions(self.protocol)).get(control)
        command = action_command(action, value, self.clock()) if action else None
        if command is not None:
            self.engine.send(command[0], command[1])

    def _announce_selection(self):
        task = self.runner.task if self.runner is not None else None
        if task is not None:
            self.events.selection.emit(source=task.source, fmax=task.fmax)

    # bowing ----------------------------------------------------------------------
    def set_bowing(self, on):
        """Put the bow on the string (True) or lift it (False), with the hand's current gesture."""
        if not self.accepting:
            return
        if self.playing:
            self.runner.set_bowing(on)
        else:
            self.engine.set_bowing(bool(on))
        self.events.bowing.emit(on=bool(on))

    def set_gesture(self, name):
        """How the virtual hand moves the handle: ``strokes`` (scripted), ``hold``, or ``live`` (the mouse)."""
        if name not in GESTURES:
            raise UserError(f"gesture {name!r}: allowed are {', '.join(GESTURES)}")
        if not self.accepting:
            return
        if self.playing:
            self.runner.set_gesture(name)
        else:
            self.engine.set_gesture(name)
        self.events.gesture.emit(name=name)

    def bow_press(self, x_m):
        """The mouse took the bow at ``x_m`` (m): the virtual hand follows it and the bow touches."""
        if not self.accepting:
            return
        self.set_gesture("live")
        self._hand_target(x_m)
        self.set_bowing(True)

    def bow_move(self, x_m):
        if self.accepting:
            self._hand_target(x_m)

    def bow_release(self):
        self.set_bowing(False)

    def _hand_target(self, x_m):
        if self.playing:
            if self.runner.gesture == "live":
                self.runner.loop.set_hand_target(x_m)
        else:
            self.engine.set_hand_target(x_m)

    # the timer ----------------------------------------------------------------------
    def poll(self):
        """Called by the GUI's timer: messages, engine state, telemetry, MIDI, status. Never waits."""
        host = self.host
        if host is None:
            return
        for kind, text in host.drain():
            self.message(text, level="fault" if kind in ("fault", "error") else "notice")
        self._announce_engine()
        self._follow_engine(host)
        block = host.read()
        if block is not None:
            self.events.telemetry.emit(block=block)
            if self.playing:
                self._feed(block)
        engine = self.engine
        if engine is None:
            return
        for control in engine.controls():
            self._midi(control)
        now = self.clock()
        if self.clearing or now >= self._next_status:
            status = engine.status()
            if now >= self._next_status:
                self._next_status = now + STATUS_PERIOD
                self.events.status.emit(status=status, lost=host.lost)
                if self.runner is None:
                    self.events.selection.emit(source=status["source"], fmax=status["fmax"])
            if self.clearing and not status["fault_latched"] and engine.status_block.force_enable:
                self.clearing = False
                if self.state == "paused" and self.runner is not None:
                    self._restart_trial()

    def _follow_engine(self, host):
        """Session transitions that wait for the engine: its start, its restart, its failure."""
        if self.state == "starting":
            if host.state == "running":
                self._begin()
            elif host.state == "failed":
                self.session.close()
                self.message(f"the engine did not start: {host.error}", level="fault")
                self._set_state("aborted")
        elif self.restarting:
            if host.state == "running":
                self.restarting = False
                self._log_engine()
                self._restart_trial()
            elif host.state == "failed":
                self.restarting = False
                self.engine_lost = True
                self.message(f"the new engine did not start either: {host.error}", level="fault")
        elif self.state in ("running", "paused") and host.state == "failed" and not self.engine_lost:
            self.engine_lost = True
            self.runner.log({"type": "engine_failed", "faults": list(host.engine.faults) if host.engine else []})
            self.message("the engine stopped (force is zero); the session is paused: press Resume to start "
                         "a new engine and repeat the trial", level="fault")
            self._set_state("paused")

    def _feed(self, block):
        n = block["end"] - block["start"]
        self.runner.loop.feed(block)
        self.runner.advance(n / self.runner.loop.rate)
        self.fed = block["end"]
        if self.runner.task is not None and self.runner.task.done:
            self._next_trial()

    def _midi(self, control):
        if control[0] == "learned":
            self.message(f"MIDI: {control[1]} bound to {control[2]}")
            return
        name, value = control[0], control[1]
        if name.startswith("knob") and name[4:].isdigit():
            self.knob(int(name[4:]) - 1, round(value * 127))
        elif name.startswith("pad") and name[3:].isdigit() and value > 0:
            self.pad(int(name[3:]) - 1)

    def message(self, text, level="info"):
        self.events.message.emit(text=str(text), level=level)

    # shutting down -----------------------------------------------------------------
    def close(self):
        """Abort a session in progress and stop the engine (waits for it)."""
        if self.state == "starting":
            self.abort()
        elif self.state in ("running", "paused"):
            self.runner.log({"type": "abort", "reason": "console closed"})
            self._end("aborted")
        if self.host is not None:
            self.host.stop(wait=True)
            self.host = None
