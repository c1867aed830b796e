"""Fixtures for the GUI tests (pytest-qt, offscreen).

Qt must find the offscreen platform before anything imports it, so the
environment is set here, at collection time. One console (with its preview
engine) serves every test of this folder: starting an engine costs seconds,
and it stops when the folder's tests are done (not at the end of the run).
Its watchdog allows 0.5 s without a heartbeat instead of 80 ms: the engine
tests check the watchdog; here a machine shared with other test runs must not
trip it (a tripped engine pauses the session, which a test would then wait on).
"""

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import shutil  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"
ENGINE_START = 180.0  # s: generous; a cold numba cache on a loaded machine is slow


def wait_until(app, predicate, timeout, step=0.01):
    """Run the event loop until ``predicate()`` holds; fail after ``timeout`` s."""
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise AssertionError(f"timed out after {timeout:g} s waiting for {predicate}")
        app.processEvents()
        time.sleep(step)


def line_within(proc, timeout):
    """The next line ``proc`` writes on stdout; fail (killing it) when none comes within ``timeout`` s.

    A bare ``readline`` waits forever on a child that hangs (a full run once did: the probe stayed
    blocked after its console failed), so the suite would never end."""
    import selectors

    with selectors.DefaultSelector() as sel:
        sel.register(proc.stdout, selectors.EVENT_READ)
        if not sel.select(timeout):
            proc.kill()
            raise AssertionError(f"no line from {proc.args[:4]} within {timeout:g} s: {proc.stderr.read()[-3000:]}")
    return proc.stdout.readline()


_ANSWERING = []  # answer_question's timers, stopped by idle_console before the next test


def answer_question(console, qtbot, button):
    """Click ``button`` (a ``QMessageBox.StandardButton``) of the console's next question once it is open.

    The question (``Console.confirm``) runs its own event loop, so the answer is set up before the
    action that asks: a timer looks for the open question every 10 ms and clicks. It gives up 60 s after
    its first look, not after it was set up: its first look comes only once the GUI thread is back in an
    event loop, late on a loaded machine. ``idle_console`` stops one a failed test left behind.
    """
    from PySide6.QtCore import Qt, QTimer

    timer = QTimer(console)
    timer.setInterval(10)
    _ANSWERING.append(timer)
    deadline = None

    def click():
        nonlocal deadline
        box = console.confirmation
        deadline = deadline or time.monotonic() + 60.0
        if (box is None or not box.isVisible()) and time.monotonic() < deadline:
            return
        timer.stop()
        _ANSWERING.remove(timer)
        timer.deleteLater()
        assert box is not None, "no question was asked"
        qtbot.mouseClick(box.button(button), Qt.MouseButton.LeftButton)

    timer.timeout.connect(click)
    timer.start()


@pytest.fixture(autouse=True)
def no_quit_left_behind(request):
    """Fail the test that called ``QApplication.exit``/``quit`` with no event loop running: Qt keeps "quit now"
    set, and every later ``QDialog.exec()`` in the process returns at once with its question still open (two
    whole runs failed their abort test that way, after a test of ``studyapp gui --screenshot``'s exit)."""
    yield
    if "qapp" not in request.fixturenames:
        return
    from PySide6.QtCore import QEventLoop, QTimer

    loop = QEventLoop()
    QTimer.singleShot(0, lambda: loop.exit(0))
    assert loop.exec() == 0, "this test left Qt quitting: it called QApplication.exit or quit with no loop running"


@pytest.fixture(scope="package")
def console(qapp):
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    controller = SessionController(audio="device", midi="first", hang_timeout=0.5)
    window = Console(controller)
    window.resize(1400, 900)
    window.show()
    assert window.choose_protocol(str(DEMO))
    wait_until(qapp, lambda: controller.engine is not None or controller.host.state == "failed", ENGINE_START)
    assert controller.host.state == "running", controller.host.error
    yield window
    window.shut_down()  # close() mid-session would ask (Console.confirm)


def make_idle(console, qapp, timeout=ENGINE_START):
    """Bring the shared console back to idle for the next test: no session, no emergency stop, the demo's
    preview engine running, bow lifted.

    A test that lost its engine (the worker died, or hung past the watchdog: the host "failed") left the
    console at rest without one, and nothing at rest starts a new one: every later test of the worker then
    waited 180 s for an engine and erred (9 did in one loaded run, issue 39). So a lost engine is replaced
    here, as an experimenter does by choosing the protocol again. A console that does not settle within
    ``timeout`` fails this test, saying what it found, and is given a new engine before the next test."""
    c = console.controller

    def settled():
        if c.emergency:  # again after a clear the engine never confirmed (CLEAR_TIMEOUT gives the stop back)
            c.clear_emergency()
        return c.engine is not None and c.state in ("idle", "finished", "aborted")

    def new_engine():
        if c.in_session:
            console.abort_session()
        assert console.choose_protocol(str(DEMO)), console.setup.error.text()

    def settle():
        try:
            wait_until(qapp, settled, timeout)
        except AssertionError as e:  # say what the console was doing (a full CI run once timed out here, 3 times)
            found = (f"{e}: state {c.state!r}, engine {c.engine!r}, host {c.host.state if c.host else None!r}; "
                     f"console log: {console.log.toPlainText()[-1500:]}")
            new_engine()  # the next test starts from a new engine, not from this one's stall
            raise AssertionError(found) from None

    while _ANSWERING:  # a test that failed before its question came: its answer must not outlive it
        _ANSWERING.pop().stop()
    if c.in_session:
        console.abort_session()
    lost = c.host is None or c.host.state in ("failed", "stopped")
    if lost or c.protocol is None or Path(c.protocol.path) != DEMO:  # or a test that failed midway left its own
        new_engine()
    settle()
    console.set_bowing(False)
    console.turn_knob(0, 0)
    return console


@pytest.fixture
def idle_console(console, qapp):
    """The shared console, its preview engine running, no session, no emergency stop, bow lifted (``make_idle``)."""
    assert console.timer.isActive(), "a test left the shared console without its poll"
    return make_idle(console, qapp)


@pytest.fixture(scope="session")
def xvfb_display():
    xvfb = shutil.which("Xvfb")
    if xvfb is None:
        pytest.skip("Xvfb not installed (Debian xvfb, listed in scripts/system-deps.txt)")
    read, write = os.pipe()
    proc = subprocess.Popen([xvfb, "-displayfd", str(write), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
                            pass_fds=(write,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write)
    try:
        with os.fdopen(read) as f:
            number = f.readline().strip()
        if not number.isdigit():
            pytest.fail(f"Xvfb did not report a display (exit code {proc.poll()})")
        yield f":{number}"
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
