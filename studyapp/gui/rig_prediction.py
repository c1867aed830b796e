"""The rig check's prediction off the GUI thread: a ``QRunnable`` on a ``QThreadPool`` of its own.

``RigPrediction.run(req)`` returns at once: a cached result (rig_check.PredictionCache,
per protocol hash, latency, packet and rate; kept on disk between launches) is announced straight away,
else the prediction (``predict(req, progress=...)``, 20-25 s of one core for
nine conditions over 5 seeds) runs on a pool thread at the lowest CPU
priority (the engine's worker and the GUI come first), reporting
``progress(done, total, condition)`` and then ``finished(key, prediction)``
through queued signals, so the views are touched on the GUI thread only.

One job runs at a time, on a pool of this object's own: another console's
predictions (a second window, the tests' consoles) never hold it. A request
that stops being current (another protocol or device chosen) has its job
stopped at its next progress report, or as it starts if it was still queued:
at the lowest priority on a busy machine, a stale job left to finish would
hold the thread for minutes. ``cancel()`` (the console closing) stops every
job the same way; the pool, a child of this object, waits for its running job
when it is destroyed.
"""

import os
import threading

from PySide6.QtCore import QObject, QRunnable, QThreadPool, Signal

from studyapp.live import rig_check


class _Signals(QObject):
    progress = Signal(object, int, int, str)  # key, done, total, condition
    finished = Signal(object, object)  # key, prediction
    failed = Signal(object, str)  # key, why


class _Gone(Exception):
    """The job was cancelled: it stops at its next progress report."""


class _Job(QRunnable):
    def __init__(self, req, predict, signals, cancelled):
        super().__init__()
        self.req, self.predict, self.signals, self.cancelled = req, predict, signals, cancelled

    def _emit(self, name, *args):
        """Tell the GUI thread; False once the job is cancelled or the receiver is gone (the console closed)."""
        if self.cancelled.is_set():
            return False
        try:
            getattr(self.signals, name).emit(*args)
        except RuntimeError:  # its QObject was deleted
            return False
        return True

    def _progress(self, done, total, name):
        if not self._emit("progress", self.req.key, done, total, name):
            raise _Gone

    def run(self):
        if self.cancelled.is_set():  # stopped while it waited in the queue
            return
        try:  # this thread only: Linux schedules threads as tasks
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), 19)
        except (OSError, AttributeError):
            pass
        try:
            result = self.predict(self.req, progress=self._progress)
        except _Gone:
            return
        except Exception as exc:  # a view must say the check failed, not hang on "predicting"
            self._emit("failed", self.req.key, f"{type(exc).__name__}: {exc}")
            return
        self._emit("finished", self.req.key, result)


class RigPrediction(QObject):
    progress = Signal(int, int, str)
    finished = Signal(object, object)  # request, prediction
    failed = Signal(str)

    def __init__(self, predict=rig_check.predict, parent=None, pool=None):
        super().__init__(parent)
        self.predict = predict
        if pool is None:
            pool = QThreadPool(self)
            pool.setMaxThreadCount(1)
        self.pool = pool
        # on disk for the model's own predictions only: a test's stand-in must never be shown as a rig's
        self.cache = rig_check.PredictionCache(rig_check.cache_path() if predict is rig_check.predict else None)
        self.current = None  # the request being shown
        self._running = {}  # key -> (request, its cancel event), while its job is queued or runs
        self._signals = _Signals()
        self._signals.progress.connect(self._progress)
        self._signals.finished.connect(self._finished)
        self._signals.failed.connect(self._failed)

    @property
    def busy(self):
        return self.current is not None and self.current.key in self._running

    def result(self, req):
        return self.cache.get(req) if req is not None else None

    def run(self, req):
        self.current = req
        self._stop(keep=None if req is None else req.key)
        if req is None:
            return
        kept = self.cache.get(req)
        if kept is not None:
            self.finished.emit(req, kept)
        elif req.key not in self._running:
            cancelled = threading.Event()
            self._running[req.key] = (req, cancelled)
            self.pool.start(_Job(req, self.predict, self._signals, cancelled))

    def cancel(self):
        """Stop every job: a queued one as it starts, a running one at its next progress report."""
        self.current = None
        self._stop(keep=None)

    def _stop(self, keep):
        for key in [k for k in self._running if k != keep]:
            self._running.pop(key)[1].set()

    def _progress(self, key, done, total, name):
        if self.current is not None and key == self.current.key:
            self.progress.emit(done, total, name)

    def _finished(self, key, prediction):
        if key not in self._running:  # stopped just after it finished: not current any more
            return
        req, _ = self._running.pop(key)
        self.cache.put(req, prediction)
        if self.current is not None and key == self.current.key:
            self.finished.emit(req, prediction)

    def _failed(self, key, why):
        self._running.pop(key, None)
        if self.current is not None and key == self.current.key:
            self.failed.emit(why)
