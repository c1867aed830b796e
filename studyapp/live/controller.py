"""One study session driven through the real-time engine: the facade the console and tests use. No Qt.

The study logic lives in ``studyapp.experiment``: ``Session`` (the folder,
schedule and crash-safe log) and ``SessionRunner`` (the tasks, everything
logged). ``SessionController`` connects them to the engine and to whoever
plays (a person with MIDI or on-screen knobs, or the simulated participant):
its methods are the experimenter's and the participant's actions, and it
announces what changes through ``events`` (``evented.EventGroup``) for the
views. Its parts, one idea each:

    states.py       the states and the transition functions (``fire``)
    apparatus.py    the engine and the trial's loop: the only sender of commands to the worker
    steps.py        a trial or page started, held and ended on the engine
    controls.py     knobs and pads: routing, pickup, page settle, latency
    hand.py         the bow and the hand's gesture, the mouse's bow pad
    devices.py      the device: chosen, its handshake and health, the rig it makes (rig_check.py)
    status_watch.py the status bar's events; a clear confirmed, or the stop given back after CLEAR_TIMEOUT
    trial_media.py  the audio recording and its cues, the reference tone, trial health

Time. ``poll()`` (a GUI timer calls it) never waits: it passes on the
engine's messages, follows the engine's state, reads the telemetry written
since the last call and, while a trial runs, hands it to the trial's
``EngineLoop`` (``consume``) and calls ``runner.advance(n / rate)``: the
task's clock, the stability verdict (the worker's own, published with every
block) and the logged events follow the samples the engine really ran.

Steps are announced by the ``trial`` event with their ``phase`` (``page``,
``practice`` or ``trial``) and ``number`` ``of`` the steps of that phase ("Practice
1 of 2", "Trial 2 of 12"); a page also by the ``page`` event (``kind``,
``title``, ``text`` in Markdown, ``by``: who acknowledges it, ``step``,
``tone_hz``, ``level_dbfs``). ``acknowledge_page(by)`` is the participant's
Continue button or the experimenter's confirm (the only one a calibration page
takes). A refused confirm is a console message and a ``refused`` event with
the reason (reasons name knobs, never conditions). Pause holds the step and
ignores the participant's controls; resume gives the settings back.

Notes and sound: ``add_note`` (experiment/session_notes.py: in the running
session, or after it in the latest session's log), ``set_volume`` (dB) and
``set_mute`` (master_sound.py: sent again to every engine that comes up;
``volume_applied`` when the preview's volume knob set it),
each logged during a session.
"""

import time
from pathlib import Path

from studyapp.engine.config import HANG_TIMEOUT
from studyapp.engine.events import DeviceHealth, DeviceInfo
from studyapp.engine.load_margin import busy_warning, load_per_core
from studyapp.engine.safety import force_off_text
from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.enrolment import apparatus_is_simulated, check_same_player
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.results_folder import used_rows_text
from studyapp.experiment.schedule import counted
from studyapp.experiment.session import Session, check_participant
from studyapp.experiment.session_notes import add_note, note_event
from studyapp.live import states
from studyapp.live.apparatus import Apparatus, preview_actions
from studyapp.live.controls import PAGE_SETTLE_S, Controls  # noqa: F401 - PAGE_SETTLE_S: the tests' and scripts' too
from studyapp.live.engine_host import EngineHost
from studyapp.live.evented import EventGroup
from studyapp.live.hand import Hand
from studyapp.live.master_sound import MasterSound
from studyapp.live.devices import Devices, rig_words
from studyapp.live.states import REST, TRANSITIONS, State
from studyapp.live.status_watch import StatusWatch
from studyapp.live.trial_media import TrialMedia


def instructions_for(protocol, task):
    """A task's instructions (none for a page: its text is the ``page`` event's)."""
    return protocol.task(task).instructions.strip() if task in protocol.specs else ""


class SessionController:
    def __init__(self, audio="device", midi="first", device=None, realtime=True, hang_timeout=None,
                 clock=time.monotonic, make_host=EngineHost):
        self.apparatus = Apparatus(audio, midi, device, realtime, hang_timeout, make_host)
        self.clock = clock
        self.events = EventGroup("protocol", "engine", "state", "trial", "knob", "selection", "bowing", "gesture",
                                 "telemetry", "status", "message", "response", "pickup", "page", "refused",
                                 "volume", "device", "device_health")
        self.controls = Controls(self)
        self.media = TrialMedia(self)
        self.hand = Hand(self)
        self.protocol = None
        self.session = None
        self.runner = None
        self.state = State.IDLE
        self.rest = State.IDLE  # the rest state a cleared emergency returns to without a session
        self.fed = 0  # end (sample number) of the telemetry read while a trial ran
        self.trial_serial = 0  # counts steps started (restarts too); tags the step's samples and controls
        self.sound = MasterSound()  # the console's master volume and mute (master_sound.py)
        self.stopped_by = "operator"  # who pressed the emergency stop last (states.emergency), or "fault"
        self.fault = ""  # the fault the engine latched on its own that stopped the session (states.fault_stop)
        self.simulated = False  # the simulated participant plays the session (apparatus "participant")
        self.abort_reason = None  # why the session is being aborted, when not the experimenter's Abort
        self.last_session = None  # the folder of the latest session started here (notes after it ends)
        self.devices = Devices(self)  # the device: its choice, its records, the rig it makes
        self.status_watch = StatusWatch(self)  # the status events, and a clear confirmed or given back

    # the state machine (states.py) --------------------------------------------------------------
    def fire(self, event):
        """Take ``event`` in the current state; returns True if the state machine moved."""
        transition = TRANSITIONS.get((self.state, event))
        if transition is None:
            return False
        self._set_state(transition(self))
        return True

    def _set_state(self, state):
        if state == State.CLEARING and self.state != State.CLEARING:
            self.status_watch.clearing_began()
        self.state = State(state)
        self.events.state.emit(state=self.state)

    emergency = property(lambda self: self.state == State.EMERGENCY)
    in_session = property(lambda self: self.session is not None)
    at_rest = property(lambda self: self.state in REST)  # no session: the engine acts live
    host = property(lambda self: self.apparatus.host)
    engine = property(lambda self: self.apparatus.engine)  # the running engine, or None (starting, failed, stopped)
    audio = property(lambda self: self.apparatus.audio)
    midi = property(lambda self: self.apparatus.midi)
    latency = property(lambda self: self.controls.latency)  # knob_latency.py
    device_info = property(lambda self: self.devices.info)  # the link device's latest handshake, or None
    controls_sent = property(lambda self: self.controls.sent)  # on-screen controls sent ...
    controls_taken = property(lambda self: self.controls.taken)  # ... and reported back (a player waits for its own)

    @property
    def playing(self):
        """True while a trial takes the participant's actions (running, engine up)."""
        return self.state == State.RUNNING and self.engine is not None

    @property
    def accepting(self):
        """True when knobs, pads and the bow act: a trial is playing, or live use outside a session."""
        return self.playing or (self.at_rest and self.engine is not None)

    # the experimenter's buttons ------------------------------------------------------------------
    def load_protocol(self, path):
        """Load and validate ``path`` (``UserError`` if invalid) and start its preview engine."""
        if self.in_session:
            raise UserError("a session is in progress: abort it before changing the protocol")
        protocol = load_protocol(path)
        self.protocol = protocol
        self.events.protocol.emit(protocol=protocol)
        self.replace_engine(self.apparatus.config(protocol, protocol.seed, preview_actions(protocol)),
                            f"preview of {protocol.study}")
        if not self.at_rest:  # a new engine: no emergency stop is latched in it
            self._set_state(self.rest)
        return protocol

    def set_device(self, device):
        """Run on ``device`` (a link's path or URL; None: the simulated device): the preview engine restarts on it."""
        self.devices.choose(device)

    def rig(self):
        """The rig the model judges (rig_check.Rig); None without a protocol."""
        return self.devices.rig()

    def replace_engine(self, config, describe):
        self.devices.info = None  # until the new engine's device shakes hands
        self.apparatus.replace(config, describe)
        self.controls.engine_replaced()

    def start_session(self, participant, results="results", resume=False, seed=None, apparatus=None, details=None,
                      logged=(), confirm_rig=None):
        """Open the participant's session (``UserError`` when refused) and start its engine.

        ``details``: ``experimenter``, ``session_number``, ``notes``, ``order_row`` (experiment/session_info.py).
        ``logged``: records for the session's log before its trials (the rig check's warning, rig_check.record).
        ``confirm_rig(question)``: asked when a resumed session last ran on another device (False: not resumed);
        None takes the change. Either way a change taken is logged (``rig_change``) and said.
        """
        if self.protocol is None:
            raise UserError("no protocol loaded: choose one first")
        if self.in_session:
            raise UserError("a session is already in progress")
        if not self.at_rest:
            raise UserError("the emergency stop is set: clear it (Resume) before starting a session")
        check_participant(participant)
        simulated = apparatus_is_simulated(apparatus)
        used = used_rows_text(Path(results) / self.protocol.study, simulated)  # before this one enrols
        if resume:
            check_same_player(results, self.protocol.study, participant, simulated)
            session = Session.resume(self.protocol, participant, results, seed=seed, **(details or {}))
            change = self.devices.change(session)
            if change is not None:
                before, now, question = change
                if confirm_rig is not None and not confirm_rig(question):
                    session.log.append(records.rig_change(before, now, accepted=False))
                    session.close()
                    raise UserError(f"not resumed: the session last ran on {rig_words(before)}, the console runs on "
                                    f"{rig_words(now)} (choose that device in Apparatus, or resume here)")
                logged = (records.rig_change(before, now), *logged)
                self.message(f"resumed on another rig: {question.rsplit('. ', 1)[0]}", level="warning")
        else:
            described = {"device": self.apparatus.device or "simulated", "engine": "real-time", **(apparatus or {})}
            session = Session.create(self.protocol, participant, results, seed=seed, apparatus=described,
                                     device=self.devices.record(), **(details or {}))
        self.session = session
        self.simulated = simulated  # who answers: stamped on every response (SessionRunner)
        self.last_session = session.folder
        for record in logged:
            session.log.append(record)
        for note in session.notes:  # what opening it found or repaired (a damaged line, a rebuilt file)
            self.message(note, level="warning")
        self.message(f"results folder {Path(results).resolve()}; before this session, {used}")
        busy = busy_warning(load_per_core(), HANG_TIMEOUT)
        if busy is not None:
            self.message(busy, level="warning")
        self.fire("open")
        return session

    def abort(self, reason=None):
        """Stop the session now; it can be resumed later (``--resume``). ``reason`` goes into the log's ``abort``."""
        self.abort_reason = reason
        try:
            self.fire("abort")
        finally:
            self.abort_reason = None

    def pause(self):
        self.fire("pause")

    def resume(self):
        """Give a paused trial back to the participant."""
        self.fire("resume")

    def emergency_stop(self, by="operator"):
        """Zero the force now (shared-memory word, then F_max 0, the bow lifted, no knob mapping).

        ``by``: who stopped, ``operator`` (the console) or ``participant`` (Esc on the participant's window)."""
        self.stopped_by = by
        self.fire("emergency")

    def fault_stop(self, fault):
        """The engine latched ``fault`` on its own: a session stops as for the emergency stop; at rest the preview
        holds it the same way (Resume clears it)."""
        if self.state in (State.RUNNING, State.PAUSED, *REST):
            self.stopped_by, self.fault = "fault", str(fault)
            self.fire("fault")

    @property
    def stop_text(self):
        """What holds the force at zero, and what to do, in the experimenter's words (the EMERGENCY state's)."""
        if self.stopped_by != "fault":
            return force_off_text(self.stopped_by)
        return (f"Stopped by a fault: {self.fault or 'the engine latched a fault'}. Force off, nothing sounds. "
                "Check the device (powered, connected), then press Resume: it re-arms the device, reopens its link "
                "if it had gone, and repeats the trial")

    def clear_emergency(self):
        """Unlatch the emergency stop (the experimenter's decision); a session's trial then starts again."""
        self.fire("clear")

    def restart_engine(self):
        """Start a new engine after the session's engine failed; its trial then starts again."""
        self.fire("restart")

    # steps (steps.py) ----------------------------------------------------------------------------
    def announce_step(self, trial):
        """Tell the views about the step that just started: knobs, counts, its page, selection, hand."""
        values = self.runner.task.knob_positions()
        for index in range(self.protocol.knobs):
            self.events.knob.emit(index=index, value=int(values.get(index, 0)))
        phase, number, of = counted(self.session.schedule, trial)
        self.events.trial.emit(trial=trial, step=trial.step, total=len(self.session.schedule),
                               instructions=instructions_for(self.protocol, trial.task), phase=phase,
                               number=number, of=of)
        page = trial.page
        if page is not None:
            self.events.page.emit(kind=page.kind, title=page.title, text=page.text, by=page.by, step=trial.step,
                                  tone_hz=page.tone_hz, level_dbfs=page.level_dbfs)
        self._announce_selection()
        self.events.gesture.emit(name=self.runner.gesture)
        self.events.bowing.emit(on=self.runner.bowing)

    def take_records(self, logged):
        """What the task logged for a control: refusals and responses announced; a response ends the step."""
        for record in logged:
            if record.get("accepted") is False:
                self.message(f"confirm refused: {record['reason']}")
                self.events.refused.emit(reason=record["reason"])
            if record.get("type") == "response":
                self.events.response.emit(response=record, step=self.runner.trial.step)
        self._announce_selection()
        self._after_task_event()

    def _after_task_event(self):
        """A response ends the trial: the next one starts at once (or the session ends)."""
        if self.runner.task is not None and self.runner.task.done:
            if self.runner.session.next_trial() is None:
                self.fire("done")
            else:
                self._set_state(states.next_step(self, self.state))

    def _announce_selection(self):
        task = self.runner.task if self.runner is not None else None
        if task is not None:
            self.events.selection.emit(source=task.source, fmax=task.fmax)

    # the participant's controls (controls.py, hand.py) -------------------------------------------------
    def knob(self, index, value):
        """Knob ``index`` (from 0) moved to ``value`` (0..127) on screen: to the worker, as MIDI would."""
        self.controls.knob(index, value)

    def pad(self, index):
        """Pad ``index`` (from 0) pressed on screen."""
        self.controls.pad(index)

    def page_age(self):
        """Seconds since the current page appeared."""
        return self.controls.page_age()

    def acknowledge_page(self, by="participant"):
        """The current page acknowledged: the participant's Continue button, or the experimenter's
        confirm. Nothing happens outside a running page."""
        runner = self.runner
        if self.playing and runner.trial is not None and runner.trial.page is not None:
            if by == "participant" and self.controls.settling("continue"):
                return
            self.take_records(runner.acknowledge_page(by, volume_db=self.sound.db))

    def set_bowing(self, on):
        self.hand.set_bowing(on)

    def set_gesture(self, name):
        self.hand.set_gesture(name)

    def bow_press(self, x_m):
        self.hand.press(x_m)

    def bow_move(self, x_m):
        self.hand.move(x_m)

    def bow_release(self):
        self.hand.release()

    # the experimenter's notes and sound --------------------------------------------------------------
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

    def volume_applied(self, gain, arrived):
        """The worker applied a volume knob's ``gain``: the master volume now (logged during a session), and
        the console's slider follows (``events.volume``); nothing is sent back. Stale reports are dropped
        (master_sound.py)."""
        record = self.sound.adopt(gain, arrived)
        if record is None:
            return
        if self.session is not None:
            self._log_session(record)
        self.events.volume.emit(db=self.sound.db)

    def set_mute(self, on):
        self._sound_event(self.sound.set_muted(on))

    def _sound_event(self, record):
        self.apparatus.send(*self.sound.commands())
        if self.session is not None:
            self._log_session(record)

    def _log_session(self, record):
        """Log ``record`` in the session's log (with the current step once its trials run)."""
        return self.runner.log(record) if self.runner is not None else self.session.log.append(record)

    # the timer ---------------------------------------------------------------------------------------
    def poll(self):
        """Called by a timer: messages, engine state, telemetry, controls, status. Never waits."""
        if self.host is None:
            return
        for notice in self.host.drain():
            if isinstance(notice, (DeviceInfo, DeviceHealth)):
                self.devices.take(notice)
            else:
                self.message(notice.text, level=notice.level, topic=getattr(notice, "topic", ""))
        self._follow_engine()
        self._read_telemetry()
        engine = self.engine
        if engine is None:
            return
        for record in engine.controls():
            self.controls.take(record)
        self.status_watch.watch(engine)

    def _follow_engine(self):
        """Announce a change of the engine's state, and let the state machine take it."""
        state = self.apparatus.state_change()
        if state is None:
            return
        info = self.host.engine.info if state == "running" else {}
        self.events.engine.emit(state=state, info=info, config=self.host.config)
        if state == "running" and self.runner is None:
            self.events.gesture.emit(name=self.protocol.gesture)
            self.events.bowing.emit(on=False)
            if self.at_rest:  # a session's engine stays on as the preview's
                self.apparatus.map_preview(self.protocol)
        if state == "running":
            self.apparatus.send(*self.sound.commands())  # the console's volume holds for every engine
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

    def message(self, text, level="info", topic=""):
        self.events.message.emit(text=str(text), level=level, topic=topic)

    def close(self):
        """Abort a session in progress and stop the engine (waits for it)."""
        if self.in_session:
            if self.runner is not None:
                self.runner.log(records.abort("console closed"))
                self._set_state(states.end(self, State.ABORTED))
            else:
                self.fire("abort")
        self.apparatus.stop()
