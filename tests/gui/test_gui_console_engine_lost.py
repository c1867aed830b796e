"""A test that loses the shared console's engine leaves the next test a running console (issue 39 item 4).

The engine's worker killed mid-session: the session waits in ENGINE_LOST; aborting it leaves the console at
rest with no engine, which nothing at rest replaces. In a loaded run one such loss made each later test of
its worker wait 180 s for an engine that never came (9 errors, "state ABORTED"). ``make_idle``, which every
test's ``idle_console`` runs, now starts a new preview engine.
"""

import pytest

from tests.gui.conftest import ENGINE_START, make_idle, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui


def test_a_console_left_without_its_engine_is_given_a_new_one(idle_console, qapp, tmp_path):
    console, c = idle_console, idle_console.controller
    console.setup.participant.setText("LOST1")
    console.setup.results.setText(str(tmp_path))
    assert console.start_session(seed=1) is not None, console.setup.error.text()
    wait_until(qapp, lambda: c.playing, ENGINE_START)
    c.engine.process.kill()
    wait_until(qapp, lambda: c.state == "engine_lost", 30)
    lost = c.host
    assert make_idle(console, qapp) is console
    assert c.host is not lost and c.host.state == "running" and c.state == "aborted" and not c.in_session
