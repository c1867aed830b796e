"""The simulated participant plays a GUI session through the console's own controls. No Qt.

``SimulatedParticipant.play(runner)`` (``studyapp.experiment``) is written
against the session runner's methods and blocks while it bows (``advance``).
In a console it runs on its own thread against ``ParticipantProxy``, which acts
out every call on the GUI thread (``act`` runs a function there and waits for
it) through the console's widgets: ``knob`` turns the on-screen knob, ``pad``
clicks the on-screen pad, ``set_bowing`` toggles the Bow button and
``set_gesture`` picks the hand's gesture, ``set_hand_target`` moves the
hand as the participant's bowing surface does (a replayed gesture,
``replay``: experiment/hand_trace.py), and ``acknowledge_page`` presses a
page's Continue (or, for the headphone level check, the experimenter's
confirm), just as a mouse would. A knob or
pad goes to the engine's worker, which applies its action and reports it
back; ``knob`` and ``pad`` return once the controller has taken that report
(as the runner's own methods return once the task has the event). The study logic stays in the runner, reached through the
same slots a person's clicks reach.

``advance(seconds)`` waits until the controller has fed that much of the
engine's output (from the moment of the call) to the trial, then returns
every sample played since the call from the telemetry ring (at least that
much; more when the participant's thread looks late, as on a loaded machine:
it counts them, simulated_participant.py), at most the newest half of the
ring: the participant hears exactly what the engine played. A look that fell
a whole ring behind used to read all of it while the worker wrote on, and the
ring's seqlock gave up (``TornRead``, seen at a load of 26 on 2 cores: the
participant raised and, before issue 31, the session sat in "Running"); the
writer would have to run 2 s during the copy of half a ring to lap it, and a
torn read is looked at again.

A paused session pauses the participant too; an aborted or closed one ends
it (``Stopped``). A play that ends while its session is still open (the
participant raised: an error, or a GUI thread that did not answer within
``gui_thread.TIMEOUT``) aborts the session, the error shown and logged as the
``abort``'s reason (``end_if_done``, from the console's timer): never a
session left "Running" with no one to answer. A trial started again (after an
emergency stop, or on a new engine after a lost one) raises ``TrialRestarted``
from the participant's next call, so it plays the trial again from its start
(the bow put back, the knob from 0), never on with what it did before. Trials are started by the
controller as soon as the previous one has its response; ``start_trial``
waits for the next one.
"""

import threading
import time

import numpy as np

from studyapp.engine.ring import TornRead
from studyapp.errors import EngineError
from studyapp.experiment.hand_trace import ReplayingHand
from studyapp.experiment.simulated_participant import SimulatedParticipant, TrialRestarted
from studyapp.live.controls import PAGE_SETTLE_S
from studyapp.live.states import ACTIVE, State

WAIT_STEP = 0.004  # s between looks at the controller's progress


class Stopped(Exception):
    """The session ended, was aborted, or the console closed while the participant played."""


class ParticipantProxy:
    """The runner's interface for ``SimulatedParticipant.play``, acted out through the console."""

    def __init__(self, controller, controls, act, stop):
        self.controller = controller
        self.controls = controls
        self._act = act
        self.stop = stop
        self._seen = controller.trial_serial
        self._trial = None
        self._given = {}

    def act(self, fn):
        # a call still queued when the session stops must do nothing once it runs
        return self._act(lambda: None if self.stop.is_set() else fn())

    def _check(self):
        if self.stop.is_set() or self.controller.state not in ACTIVE:
            raise Stopped()

    def _check_attempt(self):
        """``TrialRestarted`` once the participant's trial was started again (same step, a new attempt)."""
        self._check()
        c = self.controller
        runner = c.runner
        if (self._trial is not None and c.playing and c.trial_serial != self._seen and runner is not None
                and runner.trial is not None and runner.trial.step == self._trial.step):
            raise TrialRestarted()

    def _wait_running(self):
        while not self.controller.playing:
            self._check()
            time.sleep(WAIT_STEP)
        self._check_attempt()

    def _current(self, name):
        # The controller starts the next trial as soon as this one has its response, so the
        # participant's trial is the one it was given, unless that trial was restarted (same step).
        runner = self.controller.runner
        if runner is not None and runner.trial is not None and runner.trial.step == self._trial.step:
            return getattr(runner, name)
        return self._given[name]

    @property
    def task(self):
        return self._current("task")

    @property
    def loop(self):
        return self._current("loop")

    @property
    def gesture(self):
        """The hand's gesture in the current trial (None between trials)."""
        runner = self.controller.runner
        return runner.gesture if runner is not None else None

    def start_trial(self):
        c = self.controller
        while True:
            if c.state == State.FINISHED:
                return None
            self._check()
            if c.state == State.RUNNING and c.trial_serial > self._seen:
                self._seen = c.trial_serial
                runner = c.runner
                self._trial = runner.trial
                self._given = {"task": runner.task, "loop": runner.loop}
                return self._trial
            time.sleep(WAIT_STEP)

    def _control(self, press):
        self._wait_running()
        c = self.controller
        ticket = self.act(lambda: (press(), c.controls_sent)[1])
        while ticket is not None and c.controls_taken < ticket:
            self._check_attempt()
            time.sleep(WAIT_STEP)

    def knob(self, index, value):
        self._control(lambda: self.controls.turn_knob(index, value))

    def pad(self, index):
        self._control(lambda: self.controls.press_pad(index))

    def set_bowing(self, on):
        self._wait_running()
        self.act(lambda: self.controls.set_bowing(on))

    def set_gesture(self, name):
        self._wait_running()
        self.act(lambda: self.controls.set_gesture(name))

    def set_hand_target(self, x_m):
        """The hand's target, as the participant's bowing surface moves it (a replayed gesture)."""
        self._wait_running()
        self.act(lambda: self.controls.move_hand(x_m))

    def acknowledge_page(self, by):
        self._wait_running()
        while by == "participant" and self.controller.page_age() < PAGE_SETTLE_S:  # a reader is not that quick
            self._check()
            time.sleep(WAIT_STEP)
        self.act(lambda: self.controller.acknowledge_page(by))

    def advance(self, seconds):
        if self.loop is None:  # a page: nothing runs for the participant, time passes
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                self._check()
                time.sleep(WAIT_STEP)
            return None
        n = max(1, int(round(seconds * self.loop.rate)))
        c = self.controller
        while True:
            self._wait_running()
            engine = c.engine
            start = engine.ring.committed
            while c.engine is engine and c.fed < start + n:
                self._check_attempt()
                time.sleep(WAIT_STEP)
            if c.engine is not engine:
                continue  # a new engine after a failure starts its sample count again: listen again then
            try:
                block = engine.telemetry(since=max(start, engine.ring.committed - engine.ring.capacity // 2))
            except (TornRead, EngineError):
                continue  # the writer lapped a late look, or the engine stopped meanwhile: look again
            return {key: value for key, value in block.items() if isinstance(value, np.ndarray)}


class SimulatedSession:
    """Runs ``SimulatedParticipant(seed).play`` on a thread; ``stop()`` ends it."""

    def __init__(self, controller, controls, act, seed, replay=None, **participant):
        self.stop_event = threading.Event()
        self.controller = controller
        self.proxy = ParticipantProxy(controller, controls, act, self.stop_event)
        self.player = self.proxy if not replay else ReplayingHand(self.proxy, replay)
        self.participant = SimulatedParticipant(seed, **participant)
        self.error = None
        self.done = False
        self._thread = threading.Thread(target=self._play, name="studyapp-simulated-participant", daemon=True)

    def start(self):
        self._thread.start()
        return self

    def _play(self):
        try:
            self.participant.play(self.player)
        except Stopped:
            pass
        except Exception as exc:  # noqa: BLE001 - shown in the console, not lost on a thread
            self.error = f"simulated participant: {type(exc).__name__}: {exc}"
        finally:
            self.done = True

    def end_if_done(self):
        """True once the play has ended; its error is then shown, and a session it left unfinished is aborted
        with the error as the reason: no one answers any more, so it is never left "Running" (issue 31)."""
        if not self.done:
            return False
        c = self.controller
        if self.error:
            c.message(self.error, level="error")
        if c.in_session:
            c.message("the simulated participant stopped before the session's end: the session is aborted "
                      "(resume it to go on)", level="error")
            c.abort(reason=self.error or "the simulated participant stopped before the session's end")
        return True

    def stop(self, timeout=0.0):
        """End the play; wait up to ``timeout`` s (never on the GUI thread: the player may be waiting for it)."""
        self.stop_event.set()
        if timeout and self._thread.ident is not None:
            self._thread.join(timeout)
