"""One study session driven through the real-time engine, as an explicit state machine. No Qt.

The study logic lives in ``studyapp.experiment``: ``Session`` (the folder,
schedule and crash-safe log) and ``SessionRunner`` (the tasks, everything
logged). This controller connects them to the engine and to whoever plays (a
person with MIDI or on-screen knobs, or the simulated participant), and
announces what changes through ``events`` (``evented.EventGroup``) for the
views to show.

States (``State``) and what moves between them (``TRANSITIONS``):

    IDLE / FINISHED / ABORTED   no session; the engine acts live (the "rest" states)
      --open-->  STARTING       session folder made, its engine starting
    STARTING  --engine_up-->  RUNNING (the first unfinished trial)   --engine_failed / abort--> ABORTED
    RUNNING   --pause--> PAUSED --resume--> RUNNING;  --done--> FINISHED;  --abort--> ABORTED
    RUNNING / PAUSED  --engine_failed-->  ENGINE_LOST  --restart-->  RESTARTING
    RESTARTING  --engine_up-->  RUNNING (the trial again)   --engine_failed-->  ENGINE_LOST
    any  --emergency-->  EMERGENCY  --clear-->  CLEARING  --cleared-->  RUNNING (the trial again) or rest

An event a state does not list is ignored. Each transition is one method,
which acts and returns the next state.

Time. ``poll()`` (a GUI timer calls it) never waits: it passes on the
engine's messages, follows the engine's state, reads the telemetry written
since the last call and, while a trial runs, hands it to the trial's
``EngineLoop`` (``consume``) and calls ``runner.advance(n / rate)``: the
task's clock, the stability verdict and the logged events follow the samples
the engine really ran. The stability verdict is the worker's own, published
with every block.

Knobs and pads. Every control, MIDI or on screen, goes to the worker (an
on-screen one as a ``Control`` command), which applies its action through the
mapping in force: the preview's ``default_actions`` outside a session (knob 1
F_max on its logarithmic scale, knob 2 volume, pad i the i-th condition), the
trial's mapping during one (``engine_loop``). The worker reports each control
back (``events.Applied``, tagged with the trial's number), and the controller
hands those of the current trial to the runner, which logs them and keeps the
task's state. Their knob-to-effect latencies are shown and logged
(``knob_latency``).

Pickup. A physical knob that sets a level acts only once it has passed
through the level in force (the worker's soft takeover, engine/pickup.py): at
a trial start (F_max 0) and after a pause. Until then the worker reports it
``pending_pickup`` and the controller announces ``pickup`` (the views show
"turn the knob down to pick up"); the task never sees it. Once it acts, a
``pickup`` record (control, trial, when: the trial's clock in s, ignored: the
messages it took) goes to the session log.

Trial health. The engine's counters (``deadline_misses``, ``audio_underruns``,
``faults``, ``events_dropped``) are read when a trial starts and when it ends
(its response, the session's end, or its engine lost); their differences are
logged as a ``trial_health`` record (``underruns`` for the audio underruns),
which export carries as columns.

Audio kept with the data. Each time a session's engine comes up
(``_log_engine``) the controller asks it to record what the participant hears
into the session folder (``RecordAudio``: audio.wav, then audio-2.wav, ... for
a restarted engine or a resumed session; the worker picks the free name), and
stops it when the session ends. Each trial's start (right after its knob
mapping, so at the same block boundary) and end is sent as an ``AudioCue``:
the worker writes it to audio_cues.csv at its own audio frame counter
(engine/audio_recorder.py), so no sample position crosses the process
boundary.

Notes and sound. ``add_note`` logs the experimenter's note (``note`` event,
experiment/session_notes.py) in the running session, or after it in the
latest session's log; ``set_volume`` (dB) and ``set_mute`` hold the
console's master volume (session/master_sound.py: the engine's own
``SetVolume`` and ``SetMute``, sent again to every engine that comes up),
each change logged as a ``volume`` or ``mute`` event during a session.

Engines. A protocol gets a *preview* engine with every condition it names.
Starting a session starts a fresh engine seeded with the session's seed; once
the session ends it stays as the preview engine.

Pages. A page step (welcome, instructions, a break, the headphone level
check, ...: ``studyapp.experiment.pages``) holds the loop silent: F_max 0,
the bow lifted, an empty knob mapping tagged with the step's own number, so
the confirm pad still reaches the page (as a pad press the worker reports
back). Each step is announced by the ``trial`` event with its ``phase``
(``page``, ``practice`` or ``trial``) and its ``number`` ``of`` the steps of
that phase (of its task, for trials: "Practice 1 of 2", "Trial 2 of 12");
a page also by the ``page`` event (``kind``, ``title``, ``text`` in
Markdown, ``by``: who acknowledges it, ``step``, ``tone_hz``,
``level_dbfs``). ``acknowledge_page(by)`` is the participant's Continue
button or the experimenter's confirm. A calibration
page sends ``ReferenceTone(tone_hz, level_dbfs)`` when it starts and
``ReferenceTone(level_dbfs=None)`` when it ends (acknowledged, paused,
stopped, or the session ended); its acknowledgement is logged with the tone,
the level and who confirmed it. A refused confirm (a pad press the task
does not accept yet) is a console message and a ``refused`` event with the
reason, which the participant window shows (reasons name knobs, never
conditions).

Pause holds the loop (F_max 0, bow lifted, no knob mapping), stops the task's
clock and ignores the participant's controls; resume gives the settings back.
Emergency stop: at once, the engine's ``force_enable`` word in shared memory
is cleared, with the reason "operator" (the worker latches a fault and zeroes its force scale at its next
block, ``studyapp.engine.safety``), F_max is set to 0, the bow lifted, the
knobs unmapped. ``clear_emergency`` unlatches it and, once the engine reports
it cleared, starts the current trial again from its beginning (as a resumed
session does: an adjustment trial from F_max = 0), never back at the F_max
that was in force. Engine failure: if the worker dies or hangs during a
session (its watchdog zeroes the force), the session waits in ENGINE_LOST;
``restart_engine`` starts a new engine and, once it runs, the current trial
again from its beginning.
"""

import time
from enum import StrEnum

from studyapp.engine import commands as cmd
from studyapp.engine.config import EngineConfig
from studyapp.engine.events import Learned
from studyapp.engine.safety import SafetyLimits, force_off_text
from studyapp.errors import UserError
from studyapp.experiment.data_modes import file_mode
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.schedule import counted
from studyapp.experiment.session import Session, check_participant
from studyapp.experiment.session_info import order_text
from studyapp.experiment.session_notes import add_note, note_event
from studyapp.experiment.session_runner import SessionRunner
from studyapp.experiment.tasks import task_type
from studyapp.experiment.trial_health import HEALTH
from studyapp.model.limits import CONSOLE_GESTURES as GESTURES
from studyapp.session.engine_host import EngineHost
from studyapp.session.engine_loop import EngineLoop
from studyapp.session.evented import EventGroup
from studyapp.session.knob_latency import KnobLatency
from studyapp.session.master_sound import MasterSound

AUDIO_FILE = "audio.wav"  # what the participant heard, in the session folder (audio-2.wav, ... per engine run)
STATUS_PERIOD = 0.25  # s between status events (the status bar needs no more)
# s a page shows before the participant can end it: the second press of a double press on a trial's
# confirm pad would otherwise end the page that follows it unread (logged, not announced)
PAGE_SETTLE_S = 0.5


class State(StrEnum):
    IDLE = "idle"
    STARTING = "starting"
    RUNNING = "running"
    PAUSED = "paused"
    EMERGENCY = "emergency"
    CLEARING = "clearing"
    ENGINE_LOST = "engine_lost"
    RESTARTING = "restarting"
    FINISHED = "finished"
    ABORTED = "aborted"


REST = (State.IDLE, State.FINISHED, State.ABORTED)
EVERY = tuple(State)


def _table(*rows):
    table = {}
    for states, event, method in rows:
        for state in states:
            table[(state, event)] = method
    return table


TRANSITIONS = _table(
    (REST, "open", "_open"),
    ((State.STARTING,), "engine_up", "_begin"),
    ((State.STARTING,), "engine_failed", "_start_failed"),
    ((State.STARTING,), "abort", "_abort_unbegun"),
    ((State.RUNNING,), "pause", "_pause"),
    ((State.PAUSED,), "resume", "_resume"),
    ((State.RUNNING, State.PAUSED, State.EMERGENCY), "done", "_finish"),
    ((State.RUNNING, State.PAUSED, State.ENGINE_LOST, State.RESTARTING, State.CLEARING, State.EMERGENCY),
     "abort", "_abort"),
    ((State.RUNNING, State.PAUSED), "engine_failed", "_lose_engine"),
    ((State.ENGINE_LOST,), "restart", "_restart_engine"),
    ((State.RESTARTING,), "engine_up", "_restart_trial"),
    ((State.RESTARTING,), "engine_failed", "_restart_failed"),
    (EVERY, "emergency", "_emergency"),
    ((State.EMERGENCY,), "engine_up", "_hold_new_engine"),
    ((State.EMERGENCY,), "clear", "_clear"),
    ((State.CLEARING,), "cleared", "_cleared"),
    ((State.CLEARING,), "engine_failed", "_clear_failed"),
)


def scene_conditions(protocol):
    """Every condition the protocol names, in the order it first names them."""
    names = []
    for task in protocol.tasks:
        for name in protocol.task(task).conditions:
            if name not in names:
                names.append(name)
    return names


def instructions_for(protocol, task):
    """A task's instructions (none for a page: its text is the ``page`` event's)."""
    return protocol.task(task).instructions.strip() if task in protocol.specs else ""


def trial_actions(trial, task):
    """The knob mapping the worker applies during a trial: the task type's (``knob_actions``)."""
    return task_type(trial.task).knob_actions(trial, task)


def _control_index(name, prefix):
    rest = name[len(prefix):]
    return int(rest) - 1 if name.startswith(prefix) and rest.isdigit() else None


class SessionController:
    def __init__(self, audio="device", midi="first", device=None, realtime=True, hang_timeout=None,
                 clock=time.monotonic, make_host=EngineHost):
        self.audio = audio
        self.midi = midi
        self.device = device
        self.realtime = realtime
        self.hang_timeout = hang_timeout
        self.clock = clock
        self.make_host = make_host
        self.events = EventGroup("protocol", "engine", "state", "trial", "knob", "selection", "bowing", "gesture",
                                 "telemetry", "status", "message", "response", "pickup", "page", "refused")
        self.protocol = None
        self.host = None
        self.session = None
        self.runner = None
        self.state = State.IDLE
        self.rest = State.IDLE  # the rest state a cleared emergency returns to without a session
        self.fed = 0  # end (sample number) of the telemetry read while a trial ran
        self.trial_serial = 0  # counts trials started (restarts too); tags the trial's samples and controls
        self.latency = KnobLatency()
        self.controls_sent = 0  # on-screen controls sent to the worker ...
        self.controls_taken = 0  # ... and reported back by it (a player may wait for its own)
        self._engine_state = None
        self._next_status = 0.0
        self._pickup = {}  # control -> messages ignored while it waits for pickup
        self._health = None  # the engine and its counters when the current trial started
        self._page_shown = 0.0  # self.clock() when the current page appeared
        self._tone = False  # a calibration page's reference tone is playing
        self.sound = MasterSound()  # the console's master volume and mute (master_sound.py)
        self.last_session = None  # the folder of the latest session started here (notes after it ends)

    # the state machine ----------------------------------------------------------
    def fire(self, event):
        """Take ``event`` in the current state; returns True if the state machine moved."""
        method = TRANSITIONS.get((self.state, event))
        if method is None:
            return False
        self._set_state(getattr(self, method)())
        return True

    def _set_state(self, state):
        self.state = State(state)
        self.events.state.emit(state=self.state)

    @property
    def emergency(self):
        return self.state == State.EMERGENCY

    @property
    def in_session(self):
        return self.session is not None

    # protocol and engines ------------------------------------------------------
    def load_protocol(self, path):
        """Load and validate ``path`` (``UserError`` if invalid) and start its preview engine."""
        if self.in_session:
            raise UserError("a session is in progress: abort it before changing the protocol")
        protocol = load_protocol(path)
        self.protocol = protocol
        self.events.protocol.emit(protocol=protocol)
        self._replace_host(self._engine_config(protocol.seed, self._preview_actions()),
                           f"preview of {protocol.study}")
        if self.state not in REST:  # a new engine: no emergency stop is latched in it
            self._set_state(self.rest)
        return protocol

    def _preview_actions(self):
        return cmd.default_actions(scene_conditions(self.protocol))

    def _engine_config(self, seed, actions):
        p = self.protocol
        names = scene_conditions(p)
        config = EngineConfig(rate=p.rate, estimators={n: p.estimator_params(n) for n in names}, source=names[0],
                              fmax=0.0, gesture=p.gesture, bowing=False, seed=int(seed) % 2**32, audio=self.audio, midi=self.midi,
                              actions=actions, realtime=self.realtime, device=self.device,
                              safety=SafetyLimits(fmax_ceiling=p.fmax_ceiling))  # the hard clamp, preview too
        if self.hang_timeout is not None:
            config.hang_timeout = float(self.hang_timeout)
        return config

    def _replace_host(self, config, describe):
        old, self.host = self.host, self.make_host(config, describe).start()
        if old is not None:
            old.stop(wait=False)
        self._engine_state = None  # announced, and followed, at the next poll
        self.controls_taken = self.controls_sent  # the old engine reports nothing more

    @property
    def engine(self):
        """The running engine, or None (starting, failed or stopped)."""
        return self.host.engine if self.host is not None and self.host.running else None

    def _send(self, *commands):
        engine = self.engine
        if engine is not None:
            for command in commands:
                engine.send(command)

    # session: the experimenter's buttons ---------------------------------------------
    def start_session(self, participant, results="results", resume=False, seed=None, apparatus=None, details=None):
        """Open the participant's session (``UserError`` when refused) and start its engine.

        ``details``: ``experimenter``, ``session_number``, ``notes``, ``order_row`` (experiment/session_info.py).
        """
        if self.protocol is None:
            raise UserError("no protocol loaded: choose one first")
        if self.in_session:
            raise UserError("a session is already in progress")
        if self.state not in REST:
            raise UserError("the emergency stop is set: clear it (Resume) before starting a session")
        check_participant(participant)
        if resume:
            session = Session.resume(self.protocol, participant, results, seed=seed, **(details or {}))
        else:
            described = {"device": self.device or "simulated", "engine": "real-time", **(apparatus or {})}
            session = Session.create(self.protocol, participant, results, seed=seed, apparatus=described,
                                     **(details or {}))
        self.session = session
        self.last_session = session.folder
        for note in session.notes:  # what opening it found or repaired (a damaged line, a rebuilt file)
            self.message(note, level="warning")
        self.fire("open")
        return session

    def abort(self):
        """Stop the session now; it can be resumed later (``--resume``)."""
        self.fire("abort")

    def pause(self):
        self.fire("pause")

    def resume(self):
        """Give a paused trial back to the participant."""
        self.fire("resume")

    def emergency_stop(self):
        """Zero the force now (shared-memory word, then F_max 0, the bow lifted, no knob mapping)."""
        self.fire("emergency")

    def clear_emergency(self):
        """Unlatch the emergency stop (the experimenter's decision); a session's trial then starts again."""
        self.fire("clear")

    def restart_engine(self):
        """Start a new engine after the session's engine failed; its trial then starts again."""
        self.fire("restart")

    # transitions ---------------------------------------------------------------------
    def _open(self):
        self.runner = None
        self._replace_host(self._engine_config(self.session.seed, {}), f"session {self.session.folder}")
        self.message(f"session {self.session.folder}: {len(self.session.finished_steps())} of "
                     f"{len(self.session.schedule)} trials done, {order_text(self.session.info)}; starting the engine")
        return State.STARTING

    def _begin(self):
        """The session's engine runs: log the run, then the first unfinished trial."""
        self._begin_run()
        return self._next_trial(State.RUNNING)

    def _begin_run(self):
        self.runner = SessionRunner(self.session, make_loop=self._make_loop, progress=self.message)
        self.runner.begin()
        self._log_engine()

    def _start_failed(self):
        self.session.close()
        self.session = None
        self.message(f"the engine did not start: {self.host.error}", level="error")
        self.rest = State.ABORTED
        return State.ABORTED

    def _abort_unbegun(self):
        self.session.close()
        self.message(f"session aborted before it began: {self.session.folder}")
        self.session = None
        self.rest = State.ABORTED
        return State.ABORTED

    def _pause(self):
        self._hold(True)
        self.runner.log({"type": "pause"})
        return State.PAUSED

    def _resume(self):
        self.runner.log({"type": "resume"})
        self._hold(False)
        return State.RUNNING

    def _hold(self, on):
        """Hold the current step (pause), or give it back: a trial's loop, or a page's silence and tone."""
        if self.runner.loop is not None:
            self.runner.loop.hold(on)
            return
        self._send(cmd.InstallActions({}, trial=-self.trial_serial if on else self.trial_serial))
        self._reference_tone(not on)

    def _finish(self):
        return self._end(State.FINISHED)

    def _abort(self):
        if self.runner is None:
            return self._abort_unbegun()
        self.runner.log({"type": "abort"})
        return self._end(State.ABORTED)

    def _end(self, how):
        self._reference_tone(False)
        self._log_latency()
        self._log_health()
        self._forget_pickups()
        self.runner.finish("done" if how == State.FINISHED else str(how))
        self.session.close()
        self.message(f"session {how}: {self.session.folder}")
        self.session = None
        self.runner = None
        self.rest = how
        self.events.bowing.emit(on=False)
        self._send(cmd.RecordAudio(None))
        if self.state == State.EMERGENCY:
            return State.EMERGENCY  # the session is over, the stop still holds until cleared
        self._send(cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions(self._preview_actions()))
        return how

    def _lose_engine(self):
        self._log_health()
        engine = self.host.engine
        self.runner.log({"type": "engine_failed", "faults": list(engine.faults) if engine else []})
        self.message("the engine stopped (force is zero); the session is paused: press Resume to start "
                     "a new engine and repeat the trial", level="error")
        return State.ENGINE_LOST

    def _restart_engine(self):
        self._replace_host(self.host.config, self.host.describe)
        self.message("starting a new engine; the trial starts again once it runs")
        return State.RESTARTING

    def _restart_trial(self):
        self._log_engine()
        return self._again()

    def _again(self):
        self.runner.log({"type": "resume"})
        return self._next_trial(State.RUNNING)

    def _restart_failed(self):
        self.message(f"the new engine did not start either: {self.host.error}", level="error")
        return State.ENGINE_LOST

    def _emergency(self):
        engine = self.engine
        if engine is not None:
            engine.status_block.disable_force("operator")
        self._reference_tone(False)
        loop = self.runner.loop if self.runner is not None else None
        if loop is not None and engine is not None and loop.engine is engine:
            loop.hold(True)
        else:
            self._send(cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}))
        if self.runner is not None and self.state != State.EMERGENCY:
            self.runner.log({"type": "emergency_stop"})
        self.message(force_off_text("operator"), level="error")
        self.events.bowing.emit(on=False)
        return State.EMERGENCY

    def _hold_new_engine(self):
        """An engine came up while the emergency stop holds: it holds for this engine too."""
        if self.in_session:
            if self.runner is None:
                self._begin_run()
            else:
                self._log_engine()
        return self._emergency()

    def _clear(self):
        engine = self.engine
        self.message("emergency stop cleared by the experimenter")
        if self.runner is not None:
            self.runner.log({"type": "emergency_clear"})
        if engine is not None:
            engine.status_block.force_enable = True
            engine.clear_fault()
            return State.CLEARING
        if not self.in_session:
            return self.rest
        if self.host.state == "starting":
            return State.STARTING if self.runner is None else State.RESTARTING
        return State.ENGINE_LOST

    def _cleared(self):
        if self.in_session:
            return self._again()
        self._send(cmd.InstallActions(self._preview_actions()))
        return self.rest

    def _clear_failed(self):
        if self.in_session:
            return self._lose_engine()
        return self.rest

    # trials -------------------------------------------------------------------------
    def _log_engine(self):
        info = self.host.engine.info
        self.runner.log({"type": "engine", "rate": info["rate"], "block": info["block"], "audio": info["audio"],
                         "midi": info["midi"], "paced": info["paced"], "realtime": info["realtime"],
                         "seed": self.host.config.seed,
                         "note": "one real-time engine per session: its seed, not the trials' loop_seed, "
                                 "seeds the sensor noise"})
        self.fed = self.host.position
        # one file per engine run; participant data, with the mode of the session's other files
        self._send(cmd.RecordAudio(str(self.session.folder / AUDIO_FILE), file_mode()))

    def _make_loop(self, estimators, source, seed):
        self.trial_serial += 1
        task = self.runner.task
        actions = trial_actions(self.runner.trial, task)
        positions = {f"knob{i + 1}": int(v) for i, v in task.knob_positions().items() if v is not None}
        loop = EngineLoop(self.host.engine, estimators, source, self.protocol.gesture, self.trial_serial, actions,
                          positions)
        self._cue_audio("start")  # at the block where the trial's mapping takes force
        return loop

    def _cue_audio(self, event):
        """A row of the session's audio_cues.csv: the current trial starts or ends (engine/audio_recorder.py)."""
        trial = self.runner.trial if self.runner is not None else None
        if trial is not None:
            self._send(cmd.AudioCue(trial.step, trial.task, trial.trial, event))

    def _counters(self):
        """The session engine and its fault counters now (None without a running engine)."""
        engine = self.engine
        if engine is None:
            return None
        status = engine.status()
        return engine, {key: int(status[key]) for key in HEALTH}

    def _log_health(self):
        """Log the current trial's ``trial_health``: its engine's counters now minus at its start."""
        started, self._health = self._health, None
        if started is None or self.runner is None or self.runner.trial is None:
            return
        self._cue_audio("end")
        engine, before = started
        try:
            now = engine.status()
        except (OSError, ValueError, KeyError):
            return  # the engine is gone with its status block: nothing to count
        self.runner.log({"type": "trial_health", "trial": self.runner.trial.trial,
                         **{HEALTH[key]: int(now[key]) - before[key] for key in HEALTH}})

    def _log_latency(self):
        record = self.latency.take()
        if record is not None and self.runner is not None:
            self.runner.log(record)

    def _next_trial(self, state):
        """Start the first trial without a response (the same one again after an interruption).

        Returns ``state``, or FINISHED when no trial is left. Outside RUNNING the new trial is held.
        """
        self._reference_tone(False)
        self._log_latency()
        self._log_health()
        self._forget_pickups()
        trial = self.runner.start_trial()
        if trial is None:
            return self._end(State.FINISHED)
        self._health = self._counters()
        if trial.page is not None:
            self._show_page(trial.page)
        if state != State.RUNNING:
            self._hold(True)
        task = self.runner.task
        values = task.knob_positions()
        for index in range(self.protocol.knobs):
            self.events.knob.emit(index=index, value=int(values.get(index, 0)))
        phase, number, of = counted(self.session.schedule, trial)
        self.events.trial.emit(trial=trial, step=trial.step, total=len(self.session.schedule),
                               instructions=instructions_for(self.protocol, trial.task), phase=phase,
                               number=number, of=of)
        if trial.page is not None:
            page = trial.page
            self.events.page.emit(kind=page.kind, title=page.title, text=page.text, by=page.by, step=trial.step,
                                  tone_hz=page.tone_hz, level_dbfs=page.level_dbfs)
        self._announce_selection()
        self.events.gesture.emit(name=self.runner.gesture)
        self.events.bowing.emit(on=self.runner.bowing)
        return state

    def _show_page(self, page):
        """A page holds the loop silent under its own step number; a calibration page plays its tone."""
        self._page_shown = self.clock()
        self.trial_serial += 1
        self._send(cmd.SetFmax(0.0), cmd.SetBowing(False),
                   cmd.InstallActions({}, trial=self.trial_serial))
        self._cue_audio("start")  # a page's span in audio_cues.csv too (the level check's tone is recorded)
        self._reference_tone(page.kind == "calibration")

    def _reference_tone(self, on):
        """Start the current calibration page's reference tone (True), or end a playing one (False)."""
        trial = self.runner.trial if self.runner is not None else None
        page = trial.page if trial is not None else None
        if on and page is not None and page.kind == "calibration" and not self._tone:
            self._send(cmd.ReferenceTone(page.tone_hz, page.level_dbfs))
            self._tone = True
        elif not on and self._tone:
            self._send(cmd.ReferenceTone(level_dbfs=None))
            self._tone = False

    def _after_task_event(self):
        """A response ends the trial: the next one starts at once (or the session ends)."""
        if self.runner.task is not None and self.runner.task.done:
            if self.runner.session.next_trial() is None:
                self.fire("done")
            else:
                self._set_state(self._next_trial(self.state))

    # the participant's controls --------------------------------------------------
    @property
    def playing(self):
        """True while a trial takes the participant's actions (running, engine up)."""
        return self.state == State.RUNNING and self.engine is not None

    @property
    def accepting(self):
        """True when knobs, pads and the bow act: a trial is playing, or live use outside a session."""
        return self.playing or (self.state in REST and self.engine is not None)

    def knob(self, index, value):
        """Knob ``index`` (from 0) moved to ``value`` (0..127) on screen: to the worker, as MIDI would."""
        if self.accepting:
            self.engine.send(cmd.Control(f"knob{index + 1}", int(value) / 127))
            self.controls_sent += 1

    def pad(self, index):
        """Pad ``index`` (from 0) pressed on screen."""
        if self.accepting:
            self.engine.send(cmd.Control(f"pad{index + 1}", 1.0))
            self.controls_sent += 1

    def acknowledge_page(self, by="participant"):
        """The current page acknowledged: the participant's Continue button, or the experimenter's
        confirm (the only one a calibration page takes). Nothing happens outside a running page."""
        runner = self.runner
        if self.playing and runner.trial is not None and runner.trial.page is not None:
            if by == "participant" and self._page_settling("continue"):
                return
            self._task_records(runner.acknowledge_page(by))

    def page_age(self):
        """Seconds since the current page appeared."""
        return self.clock() - self._page_shown

    def _page_settling(self, control):
        """True (and logged) for the participant's press on a page shown less than PAGE_SETTLE_S ago."""
        since = self.page_age()
        if since >= PAGE_SETTLE_S:
            return False
        self.runner.log({"type": "acknowledge", "by": "participant", "control": control, "accepted": False,
                         "reason": f"pressed {since:.2f} s after the page appeared: taken as a double press"})
        return True

    def _control(self, record):
        """A control the worker took (``events.Applied``): show it; the current trial's go to the runner."""
        if isinstance(record, Learned):
            self.message(f"MIDI: {record.control} bound to {record.binding}")
            return
        knob = _control_index(record.control, "knob")
        pad = _control_index(record.control, "pad")
        try:
            self._take_control(record, knob, pad)
        finally:
            if record.origin == "screen":
                self.controls_taken += 1

    def _take_control(self, record, knob, pad):
        ours = self.runner is not None and self.runner.task is not None and record.trial == self.trial_serial
        live = record.trial == 0 and self.state in REST
        if not (ours or live):
            return  # a held trial's, a stale trial's, or the preview's while a session starts
        if self._picked_up(record, knob, ours):
            return
        if record.latency is not None:
            self.latency.add(record.latency, record.origin)
        if knob is not None:
            self.events.knob.emit(index=knob, value=round(record.value * 127))
        if not ours:
            return
        if self.runner.loop is not None:
            self.runner.loop.applied(record.commands)
        if knob is not None:
            self._task_records(self.runner.knob(knob, round(record.value * 127)))
        elif pad is not None and record.value > 0:
            if self.runner.trial.page is not None and self._page_settling(record.control):
                return
            self._task_records(self.runner.pad(pad))

    def _picked_up(self, record, knob, ours):
        """Follow a knob's pickup; True while it waits for it (the task must not see it)."""
        if record.pending_pickup:
            waiting = record.control in self._pickup
            self._pickup[record.control] = self._pickup.get(record.control, 0) + 1
            if not waiting:
                down = record.value > record.pickup_target
                self.events.pickup.emit(control=record.control, index=knob, pending=True,
                                        text=f"turn the knob {'down' if down else 'up'} to pick up")
            return True
        ignored = self._pickup.pop(record.control, None)
        if ignored is not None:
            self.events.pickup.emit(control=record.control, index=knob, pending=False, text="")
            if ours:
                self.runner.log({"type": "pickup", "control": record.control, "trial": self.runner.trial.trial,
                                 "when": getattr(self.runner.task, "elapsed", None), "ignored": ignored})
        return False

    def _forget_pickups(self):
        """A new mapping: a knob waiting for pickup waits for the new level (announced by its next message)."""
        for control in self._pickup:
            self.events.pickup.emit(control=control, index=_control_index(control, "knob"), pending=False, text="")
        self._pickup = {}

    def _task_records(self, records):
        for record in records:
            if record.get("accepted") is False:
                self.message(f"confirm refused: {record['reason']}")
                self.events.refused.emit(reason=record["reason"])
            if record.get("type") == "response":
                self.events.response.emit(response=record, step=self.runner.trial.step)
        self._announce_selection()
        self._after_task_event()

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
            self.runner.set_bowing(on)  # on a page (no loop) the bow stays lifted
            on = self.runner.bowing
        else:
            self.engine.send(cmd.SetBowing(bool(on)))
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
            self.engine.send(cmd.SetGesture(name))
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
            self.runner.set_hand_target(x_m)  # followed with the live gesture, and traced
        else:
            self.engine.send(cmd.SetHandTarget(float(x_m)))

    # the experimenter's notes and sound ------------------------------------------------
    def add_note(self, text):
        """Log a note (``UserError`` when refused): in the session running, else in the latest one's log."""
        event = note_event(text)
        if self.session is not None:
            record = self._log_session(event)
        elif self.last_session is not None:
            record = add_note(self.last_session, text)
        else:
            raise UserError("no session to add a note to: start one first")
        self.message(f"note logged at {record['wall']}")
        return record

    def set_volume(self, db):
        """The master volume, in dB (master_sound.py); logged during a session."""
        self._sound_event(self.sound.set_db(db))

    def set_mute(self, on):
        self._sound_event(self.sound.set_muted(on))

    def _sound_event(self, record):
        self._send(*self.sound.commands())
        if self.session is not None:
            self._log_session(record)

    def _log_session(self, record):
        """Log ``record`` in the session's log (with the current step once its trials run)."""
        return self.runner.log(record) if self.runner is not None else self.session.log.append(record)

    # the timer ----------------------------------------------------------------------
    def poll(self):
        """Called by a timer: messages, engine state, telemetry, controls, status. Never waits."""
        if self.host is None:
            return
        self._pass_messages()
        self._follow_engine()
        self._read_telemetry()
        engine = self.engine
        if engine is None:
            return
        for record in engine.controls():
            self._control(record)
        self._watch_status(engine)

    def _pass_messages(self):
        for notice in self.host.drain():
            self.message(notice.text, level=notice.level, topic=getattr(notice, "topic", ""))

    def _follow_engine(self):
        """Announce a change of the engine's state, and let the state machine take it."""
        state = self.host.state
        if state == self._engine_state:
            return
        self._engine_state = state
        info = self.host.engine.info if state == "running" else {}
        self.events.engine.emit(state=state, info=info, config=self.host.config)
        if state == "running" and self.runner is None:
            self.events.gesture.emit(name=self.protocol.gesture)
            self.events.bowing.emit(on=False)
            if self.state in REST:  # a session's engine stays on as the preview's
                self._send(cmd.InstallActions(self._preview_actions()))
        if state == "running":
            self._send(*self.sound.commands())  # the console's volume holds for every engine
            self.fire("engine_up")
        elif state == "failed":
            self.fire("engine_failed")

    def _read_telemetry(self):
        block = self.host.read()
        if block is None:
            return
        self.events.telemetry.emit(block=block)
        if self.playing and self.runner.loop is not None:
            n = self.runner.loop.consume(block)
            self.fed = block["end"]
            if n:
                self.runner.advance(n / self.runner.loop.rate)
                self._after_task_event()

    def _watch_status(self, engine):
        now = self.clock()
        clearing = self.state == State.CLEARING
        if not clearing and now < self._next_status:
            return
        status = engine.status()
        if now >= self._next_status:
            self._next_status = now + STATUS_PERIOD
            self.events.status.emit(status=status, lost=self.host.lost,
                                    knob_latency=(self.latency.last, self.latency.largest))
            if self.runner is None:
                self.events.selection.emit(source=status["source"], fmax=status["fmax"])
        if clearing and not status["fault_latched"] and engine.status_block.force_enable:
            self.fire("cleared")

    def message(self, text, level="info", topic=""):
        self.events.message.emit(text=str(text), level=level, topic=topic)

    # shutting down -----------------------------------------------------------------
    def close(self):
        """Abort a session in progress and stop the engine (waits for it)."""
        if self.in_session:
            if self.runner is not None:
                self.runner.log({"type": "abort", "reason": "console closed"})
                self._set_state(self._end(State.ABORTED))
            else:
                self.fire("abort")
        if self.host is not None:
            self.host.stop(wait=True)
            self.host = None
