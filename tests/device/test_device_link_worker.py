"""The worker's side of a link device (engine/device_link.py): ARM, the emergency stop's DISARM(1), re-arm, events."""

import time

import pytest

from studyapp.device import messages
from studyapp.device.link_device import LinkDevice
from studyapp.engine import events as ev
from studyapp.engine.device_link import DeviceLink
from tests.device.fake_device import FakeDevice


class Loop:
    cleared = 0

    def clear_device_fault(self):
        self.cleared += 1
        return True


class Events(list):
    put = list.append


@pytest.fixture
def rig():
    fake = FakeDevice()
    device = LinkDevice(fake.path, 5000.0, pings=2, ramp_ms=50)
    events = Events()
    notices = []
    link = DeviceLink(device, events, lambda text, level="info": notices.append(text))
    yield fake, device, link, events, notices
    device.close()
    fake.close()


def _host(fake, kind, count=1, timeout=2.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        found = [m for m in fake.received if isinstance(m, kind)]
        if len(found) >= count:
            return found
        time.sleep(0.002)
    return []


def test_started_arms_with_the_ramp_and_reports_the_info(rig):
    fake, device, link, events, _ = rig
    link.started()
    assert _host(fake, messages.Arm) == [messages.Arm(ramp_ms=50)]
    assert isinstance(events[0], ev.DeviceInfo) and events[0].info["serial"] == "FAKE-1"


@pytest.mark.parametrize("reason, code", [("operator", messages.EMERGENCY_STOP), ("watchdog", messages.HOST_FAULT)])
def test_force_enable_cleared_disarms_the_device_once(rig, reason, code):
    fake, device, link, _, _ = rig
    link.started()
    link.before_block(True, "parent")
    link.before_block(False, reason)
    link.before_block(False, reason)
    time.sleep(0.1)  # a second DISARM would have arrived by now
    assert _host(fake, messages.Disarm) == [messages.Disarm(reason=code)]
    assert not device.armed


def test_trial_start_rearms_and_reports_health(rig):
    fake, device, link, events, _ = rig
    link.started()
    fake.sensors(0, [(0.0, 0.0, 0.0)])
    device.exchange(type("C", (), {"sample": lambda *a: 0.0})(), 1, None, None)
    link.trial_started(3)
    assert len(_host(fake, messages.Arm, count=2)) == 2
    health = [e for e in events if isinstance(e, ev.DeviceHealth)]
    assert health[0].trial == 0 and health[0].health["frames"] == 1 and health[0].totals["samples"] == 1
    assert link.trial == 3


def test_clear_after_a_device_fault_rearms(rig):
    fake, device, link, events, _ = rig
    link.started()
    device.exchange(type("C", (), {"sample": lambda *a: 0.0})(), 1, None, None)  # silent: a device fault
    assert device.fault is not None
    loop = Loop()
    assert link.clear(loop)
    assert device.fault is None and device.armed and loop.cleared == 1
    assert len([e for e in events if isinstance(e, ev.DeviceInfo)]) == 2
