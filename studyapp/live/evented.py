"""Model events without Qt: a model announces changes, views subscribe (napari's rule).

    events = EventGroup("state", "telemetry")
    events.state.connect(view.show_state)
    events.state.emit(state="running")      # calls view.show_state(state="running")

Callbacks run synchronously, in the thread that emits, in the order they were
connected. The session controller emits only from the GUI thread (its QTimer
tick and the widgets' slots), so views may touch their widgets directly.
An exception in one callback is not caught: a broken view should fail loudly
in tests rather than leave the console silently stale.
"""


class Event:
    """One kind of change; ``connect(callback)``, ``disconnect(callback)``, ``emit(**fields)``."""

    def __init__(self, name):
        self.name = name
        self._callbacks = []

    def connect(self, callback):
        self._callbacks.append(callback)
        return callback

    def disconnect(self, callback):
        self._callbacks.remove(callback)

    def emit(self, **fields):
        for callback in list(self._callbacks):
            callback(**fields)


class EventGroup:
    """A model's events as attributes: ``group.<name>`` is an ``Event``."""

    def __init__(self, *names):
        for name in names:
            setattr(self, name, Event(name))
