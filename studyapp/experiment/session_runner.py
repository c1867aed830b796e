"""Runs a session's trials: routes knob, pad and time events to the current task,
logs them, and keeps the closed loop on the task's condition and F_max.

Whoever plays the session (the simulated participant, or the GUI for a person
with MIDI knobs) calls the same methods: ``start_trial``, ``knob``, ``pad``,
``set_bowing``, ``advance`` (run the loop for a while, which also ticks the
task, telling it whether the block was heard: ``tick(dt, heard)``, heard
being the bow on, the string sounding (its velocity not all zero), no fault
and the sound not muted (``audible``)),
``acknowledge_page`` and ``finish``. Every record a task returns is appended
to the session log with the trial's ``step`` and ``task`` (and ``practice``
true for a practice trial), and every ``response`` with ``simulated``: whether
the simulated participant gave it (``simulated``; by default as the session's
description says). The loop's faults and the stability monitor's
changes of verdict are logged too.

A page step (task ``page``) has no loop: nothing sounds while the participant
reads, and ``advance`` only ticks the page's clock. A task whose protocol
table says ``bow = "auto"`` gets the bow on the string at each trial's start
(logged as a ``bowing`` record).

The hand. Every change of the hand's gesture is logged (``gesture``, with
``from``), including the return to the protocol's gesture when the next
trial's loop starts with it. ``set_hand_target`` moves the hand's target
with the ``live`` gesture (the participant's bowing surface); those targets
and the bow's changes form the trial's ``hand_trace`` record, logged when the
trial ends (experiment/hand_trace.py), on the trial's ``clock`` (s of loop
time run).

The current trial is the state machine its task type makes
(``studyapp.experiment.tasks``). The loop is made per trial by
``make_loop(estimators, source, seed)`` with the conditions the task type asks
for (the rating trial gets all its conditions, an adjustment trial only its
own), so every adjustment trial starts from a string at rest with F_max = 0. Headless,
the default builds ``studyapp.model.loop.ClosedLoop`` in-process; the GUI passes a
factory for the real-time engine.

An event the log cannot write (a full disk) sets F_max to zero before the
``LogWriteError`` reaches the caller, which stops the session (it can be resumed).

On resume, an interrupted trial gets back what its task type restores from
the events logged before the interruption: the rating trial its knob
positions; an adjustment trial nothing, so it starts again from F_max = 0 (a
sudden return to a high F_max could be unsafe on a real device).
"""

import numpy as np

from studyapp import __version__
from studyapp.experiment import records
from studyapp.experiment.enrolment import is_simulated
from studyapp.experiment.hand_trace import HandTrace
from studyapp.experiment.session_log import LogWriteError
from studyapp.experiment.tasks import task_type


def closed_loop_factory(protocol, audio=False):
    """``make_loop`` building the model's ClosedLoop in-process for ``protocol``."""

    def make_loop(estimators, source, seed):
        from studyapp.model.loop import ClosedLoop, LoopConfig  # numba: not in the GUI, which passes its own

        config = LoopConfig(rate=protocol.rate, estimators=estimators, source=source, fmax=0.0,
                            gesture=protocol.gesture, seed=seed, audio=audio)
        return ClosedLoop(config)

    return make_loop


class SessionRunner:
    def __init__(self, session, make_loop=None, progress=None, simulated=None):
        self.session = session
        # who answers: every response says whether a machine gave it (None: as session.json says)
        self.simulated = is_simulated(session.info) if simulated is None else bool(simulated)
        self.protocol = session.protocol
        self.make_loop = make_loop or closed_loop_factory(self.protocol)
        self.progress = progress or (lambda message: None)
        self.audible = lambda: True  # the console's mute: a muted string is not heard (controller.py)
        self.trial = None
        self.task = None
        self.loop = None
        self.bowing = False
        self.gesture = None
        self.clock = 0.0  # s of loop time the current trial has run
        self.trace = HandTrace()  # the participant's gesture in the current trial (hand_trace.py)
        self._last_gesture = None  # the gesture the last trial's loop ended with
        self._loop_source = None
        self._loop_fmax = None
        self._broken = False
        self._fault = None

    def log(self, event):
        if self.trial is not None:
            practice = {"practice": True} if self.trial.practice else {}
            event = {"step": self.trial.step, "task": self.trial.task, **practice, **event}
        if event.get("type") == "response":
            event = {**event, "simulated": self.simulated}
        try:
            return self.session.log.append(event)
        except LogWriteError:
            # what is not logged did not happen: no force the log cannot account for
            if self.loop is not None:
                self.loop.set_fmax(0.0)
                self._loop_fmax = 0.0
            raise

    def begin(self):
        """Log the start of this run of the program (the first, or a resume)."""
        resumed = any(e.get("type") == "run_start" for e in self.session.events())
        done = len(self.session.finished_steps())
        self.session.log.append(records.run_start(resumed, __version__, done, len(self.session.schedule)))

    def start_trial(self):
        """Make the next unfinished trial current and return it (None when the session is done)."""
        self._log_trace()
        trial = self.session.next_trial()
        self.trial, self.task, self.loop = trial, None, None
        if trial is None:
            return None
        p = self.protocol
        kind = task_type(trial.task)
        spec = p.specs.get(trial.task)  # None for a page
        self.task = kind.start(spec, trial)
        conditions = kind.loop_conditions(trial)
        earlier = [e for e in self.session.events() if e.get("step") == trial.step]
        restored = self.task.restore(earlier)
        seed = int(np.random.SeedSequence([self.session.seed, trial.step]).generate_state(1)[0])
        estimators = {c: p.estimator_params(c) for c in conditions}
        if conditions:
            self.loop = self.make_loop(estimators, self.task.source or conditions[0], seed)
        self._loop_source = self.task.source or (conditions[0] if conditions else None)
        self._loop_fmax = None
        self._broken = False
        self._fault = None
        self.bowing = False
        self.gesture = p.gesture
        self.clock = 0.0
        self.log(records.trial_start(trial.trial, trial.condition, list(trial.conditions), bool(earlier), restored,
                                     seed))
        if self.loop is not None:
            if self._last_gesture not in (None, p.gesture):  # a change for one trial ends: logged too
                self.log(records.gesture(p.gesture, self._last_gesture, "a trial starts with the protocol's gesture"))
            self._last_gesture = p.gesture
        self._apply()
        if getattr(spec, "bow", None) == "auto":
            self.set_bowing(True)
        self.progress(f"[{trial.step + 1}/{len(self.session.schedule)}] {trial.describe()}")
        return trial

    def _apply(self):
        """Bring the loop to the task's condition and F_max (effective at the next block)."""
        if self.loop is None:
            return
        source = self.task.source
        if source is not None and source != self._loop_source:
            self.loop.set_source(source)
            self._loop_source = source
        fmax = self.task.fmax
        if fmax != self._loop_fmax:
            self.loop.set_fmax(fmax)
            self._loop_fmax = fmax

    def _handle(self, records):
        response = None
        for record in records:
            stamped = self.log(record)
            if record.get("type") == "response":
                response = stamped
        self._apply()
        if response is not None:
            self.set_bowing(False)
            self._log_trace()
            self.progress(f"    response: {self._summary(response)}")
        return records

    @staticmethod
    def _summary(response):
        return task_type(response["task"]).summary(response)

    def knob(self, index, value):
        return self._handle(self.task.knob(index, value))

    def pad(self, index):
        return self._handle(self.task.pad(index))

    def tick(self, dt, heard=None):
        return self._handle(self.task.tick(dt, self.bowing if heard is None else heard))

    def acknowledge_page(self, by, volume_db=0.0):
        """The current page acknowledged ``by`` the participant or the experimenter ([] on a trial), at the
        master volume ``volume_db`` (dB; a level check records it)."""
        if not hasattr(self.task, "acknowledge"):
            return []
        return self._handle(self.task.acknowledge(by, volume_db))

    def set_bowing(self, on):
        on = bool(on)
        if self.loop is not None and on != self.bowing:
            self.loop.set_bowing(on)
            self.bowing = on
            self.log(records.bowing(on))
            self.trace.bow(self.clock, on)

    def set_gesture(self, name):
        """Change how the virtual hand moves the handle (e.g. ``strokes``, ``hold`` to rest the bow, ``live``)."""
        if self.loop is not None and name != self.gesture:
            self.loop.set_gesture(name)
            self.log(records.gesture(name, self.gesture))
            self.gesture = self._last_gesture = name

    def set_hand_target(self, x_m):
        """The participant's hand wants the handle at ``x_m`` (m): followed with the ``live`` gesture, and traced."""
        if self.loop is not None and self.gesture == "live":
            self.loop.set_hand_target(x_m)
            self.trace.move(self.clock, x_m, self.bowing)

    def _log_trace(self):
        """The current trial's gesture as performed, once (when it ends)."""
        trace, self.trace = self.trace, HandTrace()
        record = trace.record(self.trial.trial) if self.trial is not None else None
        if record is not None:
            self.log(record)

    def advance(self, seconds):
        """Run the loop for ``seconds`` (whole samples), tick the task, and return the loop's block.

        On a page (no loop) only the page's clock runs, and None is returned."""
        if self.loop is None:
            self.tick(seconds)
            return None
        n = max(1, int(round(seconds * self.loop.rate)))
        block = self.loop.run(n)
        self.clock += n / self.loop.rate
        broken = bool(self.loop.monitor.broken)
        if broken != self._broken:
            self._broken = broken
            self.log(records.stability(broken, float(self.loop.monitor.score), self.task.fmax))
        if self.loop.fault is not None and self.loop.fault != self._fault:
            self._fault = self.loop.fault
            self.log(records.fault(str(self.loop.fault), self.task.fmax))
        self.tick(n / self.loop.rate, heard=self._heard(block))
        return block

    def _heard(self, block):
        """True when ``block`` was heard: the bow on, the string sounding, no fault, the sound not muted."""
        if not (self.bowing and self.audible() and self.loop.fault is None):
            return False
        string = block.get("string_velocity") if isinstance(block, dict) else None
        return string is None or bool(np.any(string != 0.0))

    def finish(self, reason="done"):
        """Log the end of this run; and of the session, when every trial has a response."""
        self._log_trace()
        self.trial, self.task = None, None
        complete = self.session.complete
        if complete:
            self.session.log.append(records.session_end())
        self.session.log.append(records.run_stop(reason))
        return complete
