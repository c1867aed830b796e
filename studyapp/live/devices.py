"""The session's device: which one the engines run on, what it reported, and the rig it makes. No Qt.

``choose(device)``: a link's path or URL, or None for the simulated device;
the preview engine restarts on it (refused during a session). ``take(record)``
follows the engine's device records: ``DeviceInfo`` (the handshake, kept as
``info`` and announced as the controller's ``device`` event) and
``DeviceHealth`` (a trial's frame counts: the ``device_health`` event, and a
``device_health`` record in a running session's log). ``record()`` is
session.json's ``device``; ``rig()`` the rig the model judges (rig_check.py);
``change(session)`` the question when a session is resumed on another device
than its last engine run's (compared by ``rig_words``: the name and serial).
"""

from studyapp.engine.events import DeviceInfo
from studyapp.errors import UserError
from studyapp.experiment import records
from studyapp.experiment.session import SIMULATED_DEVICE
from studyapp.experiment.session_files import EVENTS_FILE
from studyapp.experiment.session_log import read_log
from studyapp.live import device_words
from studyapp.live.apparatus import preview_actions
from studyapp.live.rig_check import rig_of


def rig_words(device):
    """A device record (session.json's ``device`` form) as the experimenter knows it: what identifies a rig."""
    if not isinstance(device, dict) or device.get("kind") == "simulated":
        return "the simulated device" if isinstance(device, dict) else "an unknown device"
    info = device.get("info")
    if isinstance(info, dict) and info.get("serial") is not None:
        return f"{info.get('name', 'a device')} (serial {info['serial']})"
    return f"the link {device.get('link', '?')}"


class Devices:
    def __init__(self, live):
        self.live = live
        self.info = None  # the link device's latest handshake (DeviceInfo), None on the simulated device
        self.steps = {}  # the engine's trial tag -> the session's step it tags (steps.py), for the health line

    def choose(self, device):
        live = self.live
        if live.in_session:
            raise UserError("a session is in progress: abort it before changing the device")
        live.apparatus.device = device or None
        self.info = None
        if live.protocol is not None:
            live.replace_engine(live.apparatus.config(live.protocol, live.protocol.seed, preview_actions(live.protocol)),
                                f"preview of {live.protocol.study}")

    def take(self, record):
        live = self.live
        if isinstance(record, DeviceInfo):
            self.info = dict(record.info)
            live.events.device.emit(info=self.info)
            return
        session = live.session
        where = device_words.step_words(record.trial, self.steps, len(session.schedule) if session else 0)
        live.events.device_health.emit(trial=record.trial, health=record.health, totals=record.totals, where=where)
        if live.runner is not None:
            live.runner.log(records.device_health(record.trial, record.health, record.totals))

    def record(self):
        """session.json's ``device``: ``kind`` simulated (latency 0) or link (its path and latest ``info``)."""
        device = self.live.apparatus.device
        if device is None:
            return dict(SIMULATED_DEVICE)
        return {"kind": "link", "link": device, "info": self.info}

    def last_used(self, session):
        """The device ``session`` last ran on: its latest ``engine`` record's (a link's handshake, or none: the
        simulated device), else session.json's ``device`` (a session that never ran an engine)."""
        engines = [e for e in read_log(session.folder / EVENTS_FILE).events if e.get("type") == "engine"]
        if engines:
            device = engines[-1].get("device")
            return {"kind": "link", "info": device} if isinstance(device, dict) else dict(SIMULATED_DEVICE)
        return session.info.get("device")

    def change(self, session):
        """(before, now, the question) when ``session`` is resumed on another device than it last ran on, else
        None (issue 41, item 9: a session resumed on the simulated device after the emulator was not asked)."""
        before, now = self.last_used(session), self.record()
        if before is None or rig_words(before) == rig_words(now):
            return None
        return before, now, (f"Session {session.folder.name} of {session.info.get('participant')} last ran on "
                             f"{rig_words(before)}; the console now runs on {rig_words(now)}. Its responses will "
                             "say which device answered each. Resume it on this rig?")

    def rig(self):
        live = self.live
        loop = (self.info or {}).get("loop")  # the handshake says whether the device runs the loop itself
        return None if live.protocol is None else rig_of(live.apparatus.config(live.protocol, 0, {}), loop)
