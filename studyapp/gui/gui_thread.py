"""Run a function on the GUI thread from any thread, and wait for its result.

Qt widgets belong to the thread that made them. A worker thread (the
simulated participant) that wants to turn an on-screen knob posts the call
through a queued signal; the GUI thread's event loop runs it between paints,
and the worker waits on a ``threading.Event`` (with a timeout, so a closing
console never deadlocks it). Called on the GUI thread itself, the function
simply runs.
"""

import threading

from PySide6.QtCore import QObject, Qt, QThread, Signal


TIMEOUT = 120.0  # s: a GUI thread on a machine at a load of 20 on 2 cores took over 10 s (issue 31)


class GuiThreadCaller(QObject):
    _posted = Signal(object)

    def __init__(self, parent=None):
        super().__init__(parent)
        self._posted.connect(self._run, Qt.ConnectionType.QueuedConnection)

    @staticmethod
    def _run(job):
        job()

    def __call__(self, fn, timeout=TIMEOUT):
        if QThread.currentThread() is self.thread():
            return fn()
        done = threading.Event()
        box = {}

        def job():
            try:
                box["value"] = fn()
            except BaseException as exc:  # noqa: BLE001 - handed back to the calling thread
                box["error"] = exc
            finally:
                done.set()

        self._posted.emit(job)
        if not done.wait(timeout):
            raise TimeoutError(f"the GUI thread did not run {getattr(fn, '__name__', fn)} within {timeout:g} s")
        if "error" in box:
            raise box["error"]
        return box.get("value")
