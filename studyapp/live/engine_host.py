"""A session's hold on one real-time engine: started and stopped without blocking, read without waiting. No Qt.

Starting the engine (``studyapp.engine.engine.Engine``) spawns its worker,
imports and loads compiled code: a few seconds. ``EngineHost.start`` does it
on a background thread, so a console keeps painting; ``state`` tells the
caller's thread when it is ``running``. The engine calls back (notices,
faults) from its watchdog thread; those land in a ``queue.SimpleQueue`` as
``events.Notice`` records (with their level) that the caller's thread drains
(``drain``), so no view is touched off its thread.

``read()`` copies every telemetry sample written since the last call from the
shared-memory ring (a seqlock copy: it never waits for the worker and the
worker never waits for it). Samples the ring no longer holds are counted in
``lost``; at 5 kHz the ring keeps 4 s, far more than the GUI's timer period.
"""

import queue
import threading

from studyapp.engine.engine import Engine
from studyapp.engine.events import Notice
from studyapp.engine.ring import TornRead
from studyapp.errors import EngineError, UserError


class EngineHost:
    def __init__(self, config, describe=""):
        self.config = config
        self.describe = describe
        self.engine = None
        self.error = None
        self.messages = queue.SimpleQueue()
        self.position = 0
        self.lost = 0
        self._cancelled = threading.Event()
        self._stopped = False
        self._after = None
        self._thread = threading.Thread(target=self._start, name="studyapp-engine-start", daemon=True)

    def start(self, after=None):
        """Start the engine in the background, once the thread ``after`` (an old engine stopping) has ended."""
        self._after = after
        self._thread.start()
        return self

    def _start(self):
        if self._after is not None:
            self._after.join()
        if self._cancelled.is_set():
            return
        try:
            engine = Engine(self.config, on_fault=lambda text: self.messages.put(Notice(text, "error")),
                            on_notice=self.messages.put, on_device=self.messages.put)
            engine.start()
        except (UserError, EngineError) as exc:
            self.error = str(exc)
            self.messages.put(Notice(self.error, "error"))
            return
        if self._cancelled.is_set():
            engine.stop()
            return
        self.engine = engine

    @property
    def state(self):
        """``starting``, ``running``, ``failed`` (could not start, or its worker died or hung) or ``stopped``."""
        if self._stopped:
            return "stopped"
        if self.error is not None:
            return "failed"
        if self.engine is None:
            return "starting"
        return "running" if self.engine.alive else "failed"

    @property
    def running(self):
        return self.state == "running"

    def read(self):
        """Telemetry since the last read (``Engine.telemetry`` layout), or None when there is none."""
        if not self.running:
            return None
        try:
            block = self.engine.telemetry(since=self.position)
        except TornRead:
            self.position = self.engine.ring.committed
            return None
        self.lost += block["start"] - self.position
        self.position = block["end"]
        return block if block["end"] > block["start"] else None

    def drain(self):
        """Every ``events.Notice`` since the last call (faults and start errors at level ``error``), and the
        device's ``events.DeviceInfo`` and ``events.DeviceHealth`` records."""
        out = []
        while True:
            try:
                out.append(self.messages.get_nowait())
            except queue.Empty:
                return out

    def stop(self, wait=True):
        """Stop the worker and free its shared memory; ``wait=False`` does it on a background thread."""
        self._stopped = True
        self._cancelled.set()

        def finish():
            if self._thread.ident is not None:
                self._thread.join()
            if self.engine is not None:
                self.engine.stop()

        if wait:
            finish()
            return None
        thread = threading.Thread(target=finish, name="studyapp-engine-stop", daemon=True)
        thread.start()
        return thread
