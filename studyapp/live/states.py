"""The live session's states and what moves between them: a table of transition functions. No Qt.

    IDLE / FINISHED / ABORTED   no session; the engine acts live (the "rest" states)
      --open-->  STARTING       session folder made, its engine starting
    STARTING  --engine_up-->  RUNNING (the first unfinished trial)   --engine_failed / abort--> ABORTED
    RUNNING   --pause--> PAUSED --resume--> RUNNING;  --done--> FINISHED;  --abort--> ABORTED
    RUNNING / PAUSED  --engine_failed-->  ENGINE_LOST  --restart-->  RESTARTING
    RESTARTING  --engine_up-->  RUNNING (the trial again)   --engine_failed-->  ENGINE_LOST
    any  --emergency-->  EMERGENCY  --clear-->  CLEARING  --cleared-->  RUNNING (the trial again) or rest
    RUNNING / PAUSED / rest  --fault-->  EMERGENCY (the engine latched a fault of its own: a device's, the loop's)
                                                  CLEARING  --clear_timeout-->  EMERGENCY (the stop holds again)

``TRANSITIONS`` maps (state, event) to a function of the controller
(``controller.SessionController``) that acts and returns the next state; an
event a state does not list is ignored (``SessionController.fire``). The
functions use the controller's parts: ``apparatus`` (the engine, the only
sender of commands), ``media`` (reference tone, audio cues, trial health),
``controls`` (pickup, latency) and ``steps`` (a trial or page started, held, ended).

Emergency stop: at once, the engine's ``force_enable`` word in shared memory
is cleared with the reason "operator", or "participant" for Esc on the
participant's window (``stopped_by``, logged with the stop; the worker latches a fault and zeroes
its force scale at its next block, ``studyapp.engine.safety``), F_max is set
to 0, the bow lifted, the knobs unmapped. Clearing unlatches it and, once the
engine reports it cleared, starts the current trial again from its beginning
(as a resumed session does: an adjustment trial from F_max = 0), never back at
the F_max that was in force. A fault the engine latches on its own during a session (a device on a link
that faulted, went silent or closed; the loop's own guard) stops the session
the same way (``fault_stop``, ``stopped_by`` "fault", the fault's text in the
state's words, ``stop_text``): the force is already zero, and a session left
"Running" with no force would take the participant's confirms against
nothing heard. Resume clears it as it clears the emergency stop (re-arming
the device, reopening its link if it had gone) and repeats the trial.
Engine failure: if the worker dies or hangs
during a session (its watchdog zeroes the force), the session waits in
ENGINE_LOST; restarting starts a new engine and, once it runs, the current
trial again from its beginning.
"""

from enum import StrEnum

from studyapp.experiment import records
from studyapp.experiment.session_info import order_text
from studyapp.experiment.session_runner import SessionRunner
from studyapp.live import steps


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
ACTIVE = tuple(state for state in State if state not in REST)  # a session is open
EVERY = tuple(State)


# opening and starting --------------------------------------------------------------------------------
def open_session(c):
    c.runner = None
    c.replace_engine(c.apparatus.config(c.protocol, c.session.seed, {}), f"session {c.session.folder}")
    c.message(f"session {c.session.folder}: {len(c.session.finished_steps())} of "
              f"{len(c.session.schedule)} trials done, {order_text(c.session.info)}; starting the engine")
    return State.STARTING


def begin(c):
    """The session's engine runs: log the run, then the first unfinished trial."""
    begin_run(c)
    return next_step(c, State.RUNNING)


def begin_run(c):
    c.runner = SessionRunner(c.session, make_loop=lambda *loop: steps.make_loop(c, *loop), progress=c.message,
                             simulated=c.simulated)
    c.runner.audible = lambda: not c.sound.muted
    c.runner.begin()
    engine_up(c)


def engine_up(c):
    """A session's engine runs: logged, recorded, its telemetry followed from now."""
    c.media.engine_up()
    c.fed = c.host.position


def next_step(c, state):
    """The next step started (held outside RUNNING) and announced; ``state``, or FINISHED when none is left."""
    trial = steps.start_step(c, held=state != State.RUNNING)
    if trial is None:
        return end(c, State.FINISHED)
    c.announce_step(trial)
    return state


def start_failed(c):
    c.session.close()
    c.session = None
    c.message(f"the engine did not start: {c.host.error}", level="error")
    c.rest = State.ABORTED
    return State.ABORTED


def abort_unbegun(c):
    c.session.close()
    c.message(f"session aborted before it began: {c.session.folder}")
    c.session = None
    c.rest = State.ABORTED
    return State.ABORTED


# pausing and ending ----------------------------------------------------------------------------------
def pause(c):
    steps.hold(c, True)
    c.runner.log(records.pause())
    return State.PAUSED


def resume(c):
    c.runner.log(records.resume())
    steps.hold(c, False)
    return State.RUNNING


def finish(c):
    return end(c, State.FINISHED)


def abort(c):
    if c.runner is None:
        return abort_unbegun(c)
    c.runner.log(records.abort(c.abort_reason))
    return end(c, State.ABORTED)


def end(c, how):
    """The session is over (``how``: FINISHED or ABORTED); the engine stays on as the preview's."""
    steps.step_ends(c)
    c.runner.finish("done" if how == State.FINISHED else str(how))
    c.session.close()
    c.message(f"session {how}: {c.session.folder}")
    c.session = None
    c.runner = None
    c.rest = how
    c.events.bowing.emit(on=False)
    c.media.stop_recording()
    if c.state == State.EMERGENCY:
        return State.EMERGENCY  # the session is over, the stop still holds until cleared
    c.apparatus.to_preview(c.protocol)
    return how


# a lost engine ------------------------------------------------------------------------------------------
def lose_engine(c):
    c.media.log_health()
    engine = c.host.engine
    c.runner.log(records.engine_failed(engine.faults_since_clear() if engine else []))  # not the stops cleared
    c.message("the engine stopped (force is zero); the session is paused: press Resume to start "
              "a new engine and repeat the trial", level="error")
    return State.ENGINE_LOST


def restart_engine(c):
    c.replace_engine(c.host.config, c.host.describe)
    c.message("starting a new engine; the trial starts again once it runs")
    return State.RESTARTING


def restart_trial(c):
    engine_up(c)
    return again(c)


def again(c):
    c.runner.log(records.resume())
    return next_step(c, State.RUNNING)


def restart_failed(c):
    c.message(f"the new engine did not start either: {c.host.error}", level="error")
    return State.ENGINE_LOST


# the emergency stop -------------------------------------------------------------------------------------
def emergency(c):
    if c.stopped_by == "fault":  # a clear the engine did not confirm gives the fault's stop back: nothing new
        return _force_off(c)
    c.apparatus.disable_force(c.stopped_by)
    if c.runner is not None and c.state != State.EMERGENCY:
        c.runner.log(records.emergency_stop(c.stopped_by))
    return _force_off(c)


def fault_stop(c):
    """The engine latched a fault of its own (``c.fault``): the force is zero already; held as an emergency stop
    (at rest too: the preview's fault is cleared by Resume, not only by an emergency stop first)."""
    if c.runner is not None:
        c.runner.log(records.emergency_stop("fault", fault=c.fault))
    return _force_off(c)


def _force_off(c):
    c.media.reference_tone(False)
    loop = c.runner.loop if c.runner is not None else None
    if loop is not None and c.engine is not None and loop.engine is c.engine:
        loop.hold(True)
    else:
        c.apparatus.silence()
    c.message(c.stop_text, level="error")
    c.events.bowing.emit(on=False)
    return State.EMERGENCY


def hold_new_engine(c):
    """An engine came up while the emergency stop holds: it holds for this engine too."""
    if c.in_session:
        if c.runner is None:
            begin_run(c)
        else:
            engine_up(c)
    return emergency(c)


def clear(c):
    c.message("emergency stop cleared by the experimenter")
    if c.runner is not None:
        c.runner.log(records.emergency_clear())
    if c.apparatus.enable_force():
        return State.CLEARING
    if not c.in_session:
        return c.rest
    if c.host.state == "starting":
        return State.STARTING if c.runner is None else State.RESTARTING
    return State.ENGINE_LOST


def cleared(c):
    if c.in_session:
        return again(c)
    c.apparatus.map_preview(c.protocol)
    return c.rest


def clear_failed(c):
    if c.in_session:
        return lose_engine(c)
    return c.rest


def _table(*rows):
    table = {}
    for states, event, transition in rows:
        for state in states:
            table[(state, event)] = transition
    return table


TRANSITIONS = _table(
    (REST, "open", open_session),
    ((State.STARTING,), "engine_up", begin),
    ((State.STARTING,), "engine_failed", start_failed),
    ((State.STARTING,), "abort", abort_unbegun),
    ((State.RUNNING,), "pause", pause),
    ((State.PAUSED,), "resume", resume),
    ((State.RUNNING, State.PAUSED, State.EMERGENCY), "done", finish),
    ((State.RUNNING, State.PAUSED, State.ENGINE_LOST, State.RESTARTING, State.CLEARING, State.EMERGENCY),
     "abort", abort),
    ((State.RUNNING, State.PAUSED), "engine_failed", lose_engine),
    ((State.ENGINE_LOST,), "restart", restart_engine),
    ((State.RESTARTING,), "engine_up", restart_trial),
    ((State.RESTARTING,), "engine_failed", restart_failed),
    (EVERY, "emergency", emergency),
    ((State.RUNNING, State.PAUSED, *REST), "fault", fault_stop),
    ((State.EMERGENCY,), "engine_up", hold_new_engine),
    ((State.EMERGENCY,), "clear", clear),
    ((State.CLEARING,), "cleared", cleared),
    ((State.CLEARING,), "clear_timeout", emergency),
    ((State.CLEARING,), "engine_failed", clear_failed),
)
