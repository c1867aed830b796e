"""The engine's status, read on the controller's timer: the status bar's events, and a clear confirmed or given back. No Qt.

``watch(engine)`` (``SessionController.poll``) reads the worker's status
block at most every ``STATUS_PERIOD`` and announces it (the ``status`` event,
with the frames lost and the knob latency; the ``selection`` event while no
session runs). While the controller is CLEARING it reads the block on every
poll: the clear is confirmed (``cleared``) once the worker has no fault
latched and its force word is set again. A clear the worker does not confirm
within ``CLEAR_TIMEOUT`` (a worker whose loop latched its own fault refuses
it) gives the emergency stop back (``clear_timeout``) with an error message
naming the fault and force state: the console is never left "Clearing" for
good. A fault latched with the force word still set is the engine's own (a
device's, the loop's guard), never a stop: during a session it stops the
session (``fault_stop``), checked at every status read.
"""

from studyapp.live.states import REST, State

STATUS_PERIOD = 0.25  # s between status events (the status bar needs no more)
CLEAR_TIMEOUT = 5.0  # s a cleared stop may wait for the worker's word that it cleared; then the stop holds again


class StatusWatch:
    def __init__(self, live):
        self.live = live
        self.next_status = 0.0
        self.clearing_since = 0.0  # the controller's clock when the last clear began

    def clearing_began(self):
        self.clearing_since = self.live.clock()

    def watch(self, engine):
        live = self.live
        now = live.clock()
        clearing = live.state == State.CLEARING
        if not clearing and now < self.next_status:
            return
        status = engine.status()
        if now >= self.next_status:
            self.next_status = now + STATUS_PERIOD
            live.events.status.emit(status=status, lost=live.host.lost,
                                    knob_latency=(live.latency.last, live.latency.largest))
            if live.runner is None:
                live.events.selection.emit(source=status["source"], fmax=status["fmax"])
        force_enabled = bool(engine.status_block.force_enable)
        if status["fault_latched"] and force_enabled and live.state in (State.RUNNING, State.PAUSED, *REST):
            live.fault_stop(status["fault"] or "safety fault")  # the engine's own: a stop clears the force word
        elif clearing and not status["fault_latched"] and force_enabled:
            live.fire("cleared")
        elif clearing and now - self.clearing_since > CLEAR_TIMEOUT:
            live.message(f"the engine did not confirm the clear within {CLEAR_TIMEOUT:g} s (fault latched: "
                         f"{bool(status['fault_latched'])}, force enabled: {force_enabled}); "
                         "the emergency stop holds: press Resume again, or restart the engine", level="error")
            live.fire("clear_timeout")
