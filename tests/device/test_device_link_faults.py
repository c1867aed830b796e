"""Issue 41, items 2-3: the worker's side of a link device (engine/device_link.py) with a stand-in device.

- the engine's own latched fault (the runaway guard, a clamp found violated) disarms the device, DISARM(2), once
  (before: the guard ramped its command to 0 and the device stayed armed);
- ``live``'s re-arm: a fault of timing (the device's WATCHDOG, the host's silence) is re-armed at once, counted and
  told; any other fault, or a failed link, stays latched.
"""

import time

from studyapp.device import messages
from studyapp.device.link_device import DISARM_EMERGENCY, DISARM_FAULT
from studyapp.engine.device_link import DeviceLink


class StubDevice:
    clock = True

    def __init__(self):
        self.disarms = []
        self.arms = 0
        self.rearms = 0
        self.armed = True
        self.fault = None
        self.fault_code = None
        self.fault_timing = False
        self.fault_time = None
        self.link_lost = False
        self.health = {"trips": 0, "silences": 0}
        self.info = {"name": "stub"}

    def disarm(self, reason):
        self.disarms.append(reason)
        self.armed = False

    def arm(self):
        self.arms += 1

    def rearm(self):
        self.rearms += 1
        self.fault = None

    def resync(self):
        pass


class StubLoop:
    def __init__(self):
        self.cleared = 0

    def clear_device_fault(self):
        self.cleared += 1


class Events:
    def __init__(self):
        self.items = []

    def put(self, item):
        self.items.append(item)


def _link(device):
    notices = []
    return DeviceLink(device, Events(), lambda text, level: notices.append(text)), notices


def test_the_engines_latched_fault_disarms_the_device_once():
    device = StubDevice()
    link, _ = _link(device)
    link.before_block(True, None, None)
    assert device.disarms == []
    for _ in range(3):
        link.before_block(True, None, "runaway: motor saturated ...")
    assert device.disarms == [DISARM_FAULT]
    link.clear(StubLoop())  # the experimenter's Resume arms it again
    assert device.arms == 1
    link.before_block(False, "operator", None)
    assert device.disarms == [DISARM_FAULT, DISARM_EMERGENCY]


def _faulted(code=None, timing=False, lost=False):
    device = StubDevice()
    device.fault = "the device reported WATCHDOG at its sample 7" if code else "host-detected: something"
    device.fault_code, device.fault_timing, device.link_lost = code, timing, lost
    device.fault_time = time.monotonic()
    return device


def test_a_watchdog_trip_or_a_silence_is_re_armed_counted_and_told():
    for code, words in ((messages.WATCHDOG, "its watchdog tripped"), (None, "heard nothing")):
        device = _faulted(code, timing=True)
        link, notices = _link(device)
        loop = StubLoop()
        assert link.rearm_after_trip(loop)
        assert device.rearms == 1 and loop.cleared == 1 and device.fault is None
        assert link.rearms == 1 and 0.0 <= link.rearm_delays[0] < 0.5
        assert len(notices) == 1 and words in notices[0]
        assert link.summary()["device_rearms"] == 1


def test_any_other_fault_stays_latched_for_the_experimenter():
    for device in (_faulted(messages.LINK_CORRUPT), _faulted(None), _faulted(messages.WATCHDOG, True, lost=True)):
        link, notices = _link(device)
        assert not link.rearm_after_trip(StubLoop())
        assert device.rearms == 0 and device.fault is not None and notices == []
