"""The worker's side of a device on a link: arming, the emergency stop, re-arming, its info and health.

A link device (studyapp/device/link_device.py) owns the sample clock and its
own safety; the worker tells it what the experimenter and the force guard
decide:

- the run starts (after the worker's priming): frames that piled up while the
  worker was busy are dropped (``resync``), then ARM(ramp): the force ramps up
  from 0 (the device's ramp, ``EngineConfig.device_ramp_ms``);
- a trial starts (``ResetString``): ARM(ramp) again, so each trial's force
  ramps up from 0 (the device restarts its ramp), and the trial's health is
  reported;
- ``force_enable`` cleared (the emergency stop: DISARM(1); the guard or the
  parent's watchdog: DISARM(2)), or a fault latched by the engine's safety
  (the runaway guard, a clamp found violated: DISARM(2)), before the block
  runs: the device's force is cut at once, and it is sent 0 N while disarmed;
- the experimenter clears the fault (``ClearFault``): a device fault (the link
  closed, failed or fell silent; the device's own WATCHDOG) is re-armed
  (``rearm``: the link reopened and the handshake redone if need be) and the
  loop's device fault cleared; else ARM again;
- ``rearm_after_trip`` (``EngineConfig.device_rearm``: ``studyapp live``):
  a fault of timing (the device's WATCHDOG trip: its force cut because the
  host's forces came late; the host's silence: no valid frame in time, on a
  link still open) is re-armed at once, counted (``rearms``; the delays from
  the host latching the fault to the ARM in ``rearm_delays``) and told to the
  parent; every other device fault stays latched for the experimenter.

Events (engine/events.py) for the console and the session records:
``DeviceInfo(info)`` once the device is armed (and after each re-arm), and
``DeviceHealth(trial, health, totals)`` at each trial's start for the one that
ended (``health`` the counts over that trial, ``totals`` since the link opened).
The status block carries the running counts (``device_*`` numbers).
"""

import time

from studyapp.device.link_device import DISARM_EMERGENCY, DISARM_FAULT
from studyapp.device.messages import WATCHDOG
from studyapp.engine import events as ev
from studyapp.errors import UserError

STATUS = {"device_frames": "frames", "device_late": "late", "device_missing": "missing", "device_lost": "lost",
          "device_corrupt": "corrupt"}


class DeviceLink:
    """``device`` (a ``LinkDevice``) as the worker drives it; ``notice(text, level)`` for the parent."""

    def __init__(self, device, events, notice):
        self.device = device
        self.events = events
        self.notice = notice
        self.trial = 0
        self._trial_start = dict(device.health)
        self._disarmed_for = None  # the force_enable reason the device was disarmed for
        self.rearms = 0  # watchdog trips re-armed (rearm_after_trip)
        self.rearm_delays = []  # s from the host reading each trip to its ARM

    @staticmethod
    def of(device, events, notice):
        """A ``DeviceLink`` for a device that owns the clock; None for any other device."""
        return DeviceLink(device, events, notice) if getattr(device, "clock", False) else None

    @property
    def info(self):
        return self.device.info

    def started(self):
        """The run begins: fresh frames, armed (ramping up from 0)."""
        self.device.resync()
        self.device.arm()
        self._trial_start = dict(self.device.health)
        self.events.put(ev.DeviceInfo(self.info))

    def before_block(self, enabled, reason, latched=None):
        """The force guard's word for this block, and the safety's latched fault (``latched``, its text or None):
        disarm the device the moment either cuts the force."""
        if self._disarmed_for is not None:
            return
        if not enabled:
            self._disarmed_for = reason
            self.device.disarm(DISARM_EMERGENCY if reason == "operator" else DISARM_FAULT)
        elif latched is not None:
            self._disarmed_for = "fault"
            self.device.disarm(DISARM_FAULT)

    def trial_started(self, trial):
        """A trial (re)starts: the last one's health, and the force ramps up from 0 again."""
        self.report(trial)
        if self.device.armed:
            self.device.arm()  # an ARM while armed restarts the device's ramp from 0

    def report(self, trial=None):
        now = dict(self.device.health)
        health = {key: now[key] - self._trial_start.get(key, 0) for key in now}
        self.events.put(ev.DeviceHealth(self.trial, health, now))
        self._trial_start = now
        if trial is not None:
            self.trial = int(trial)

    def clear(self, loop):
        """The experimenter's reset: re-arm the device (reopening the link after a device fault)."""
        self._disarmed_for = None
        try:
            if self.device.fault is not None:
                self.device.rearm()
                loop.clear_device_fault()
                self.events.put(ev.DeviceInfo(self.info))
            else:
                self.device.arm()
        except UserError as exc:
            self.notice(f"device: cannot re-arm: {exc}", "warning")
            return False
        if self.device.fault is not None:
            self.notice(f"device: cannot re-arm: {self.device.fault}", "warning")
            return False
        return True

    def rearm_after_trip(self, loop):
        """Re-arm the device after its watchdog tripped (``studyapp live``); True if it was re-armed."""
        device = self.device
        if device.fault is None or not device.fault_timing or device.link_lost:
            return False
        what = ("its watchdog tripped (the host's forces came late)" if device.fault_code == WATCHDOG
                else "the host heard nothing from it in time")
        read_at = device.fault_time
        if not self.clear(loop):
            return False
        self.rearms += 1
        self.rearm_delays.append(time.monotonic() - read_at)
        self.notice(f"device: {what}; re-armed after {1e3 * self.rearm_delays[-1]:.1f} ms (re-arm {self.rearms})",
                    "warning")
        return True

    def status(self):
        return {key: self.device.health[name] for key, name in STATUS.items()}

    def summary(self):
        return {"device": self.info, "device_health": dict(self.device.health), "device_fault": self.device.fault,
                "device_rearms": self.rearms,
                "device_rearm_max_s": max(self.rearm_delays) if self.rearm_delays else None}

    def close(self):
        self.report()
        self.device.close()
