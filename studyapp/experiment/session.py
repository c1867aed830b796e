"""A session: one participant's run of a protocol, kept on disk as it happens.

Layout (DESIGN.md "Results layout"):

    RESULTS/<study>/<participant>/<session-start>/session.json
    RESULTS/<study>/<participant>/<session-start>/events.jsonl

``session.json`` is written once, atomically, when the session is created:
the protocol (its text, validated settings and SHA-256), the app version, the
seed, the participant's enrolment index and Latin-square rows, the schedule,
and the apparatus (device, rate). Everything that happens afterwards is an
event in ``events.jsonl`` (see ``session_log``).

A trial is finished when its ``response`` event is on disk. ``resume`` reopens
the participant's session and continues at the first unfinished trial; the
schedule and the protocol come from session.json, so nothing is lost,
repeated or reordered. Creating a second session for a participant who
already has one is refused: resume it, or use another participant ID.

Participant IDs are pseudonyms (1 to 32 letters, digits, '_' or '-'); nothing
else about the participant is stored.
"""

import json
import os
from datetime import datetime
from pathlib import Path

import numpy as np

from studyapp import __version__
from studyapp.atomic import atomic_open
from studyapp.errors import UserError
from studyapp.experiment.protocol import NAME_ALLOWED, NAME_PATTERN, parse_protocol
from studyapp.experiment.schedule import Trial, build_schedule
from studyapp.experiment.session_log import SessionLog, fsync_directory, read_events, wall_time

SESSION_FILE = "session.json"
EVENTS_FILE = "events.jsonl"
FORMAT = "studyapp-session/1"


def check_participant(participant):
    if not isinstance(participant, str) or not NAME_PATTERN.fullmatch(participant):
        raise UserError(f"participant ID {participant!r}: allowed is a pseudonym of {NAME_ALLOWED}")
    return participant


def session_folders(participant_folder):
    """The session folders (holding a session.json) of one participant, oldest first."""
    folder = Path(participant_folder)
    if not folder.is_dir():
        return []
    return sorted(p.parent for p in folder.glob(f"*/{SESSION_FILE}"))


def enrolled_participants(study_folder):
    """The participant IDs with at least one session under ``study_folder``."""
    folder = Path(study_folder)
    if not folder.is_dir():
        return []
    return sorted(p.name for p in folder.iterdir() if p.is_dir() and session_folders(p))


def default_seed(protocol_seed, participant_index):
    """The session seed when none is given: reproducible from the study seed and enrolment index."""
    return int(np.random.SeedSequence([protocol_seed, participant_index]).generate_state(1)[0])


class Session:
    """An open session folder: its stored description, schedule and event log."""

    def __init__(self, folder):
        self.folder = Path(folder)
        with open(self.folder / SESSION_FILE, encoding="utf-8") as f:
            self.info = json.load(f)
        if self.info.get("format") != FORMAT:
            raise UserError(f"{self.folder / SESSION_FILE}: format {self.info.get('format')!r}: allowed is {FORMAT!r}")
        self.protocol = parse_protocol(self.info["protocol"]["text"], self.info["protocol"]["path"])
        self.schedule = [Trial.from_dict(d) for d in self.info["schedule"]]
        self.log = SessionLog(self.folder / EVENTS_FILE)

    @property
    def participant(self):
        return self.info["participant"]

    @property
    def seed(self):
        return self.info["seed"]

    @property
    def name(self):
        return self.info["session"]

    def events(self):
        return read_events(self.folder / EVENTS_FILE)

    def finished_steps(self):
        return {e["step"] for e in self.events() if e.get("type") == "response"}

    def next_trial(self):
        """The first trial without a response, or None when the session is complete."""
        done = self.finished_steps()
        return next((t for t in self.schedule if t.step not in done), None)

    @property
    def complete(self):
        return self.next_trial() is None

    def close(self):
        self.log.close()

    @classmethod
    def create(cls, protocol, participant, results, seed=None, apparatus=None):
        """A new session of ``participant`` under ``results``; refused if they already have one."""
        check_participant(participant)
        study_folder = Path(results) / protocol.study
        participant_folder = study_folder / participant
        existing = session_folders(participant_folder)
        if existing:
            raise UserError(
                f"participant {participant!r} already has a session in {existing[-1]}: "
                "allowed is --resume to continue it, or another participant ID")
        index = len([p for p in enrolled_participants(study_folder) if p != participant])
        seed = default_seed(protocol.seed, index) if seed is None else int(seed)
        schedule, squares = build_schedule(protocol, index)
        started = datetime.now().astimezone()
        folder = participant_folder / started.strftime("%Y-%m-%dT%H-%M-%S")
        suffix = 1
        while folder.exists():
            suffix += 1
            folder = participant_folder / f"{started.strftime('%Y-%m-%dT%H-%M-%S')}-{suffix}"
        info = {
            "format": FORMAT,
            "study": protocol.study,
            "participant": participant,
            "participant_index": index,
            "session": folder.name,
            "started": wall_time(),
            "app_version": __version__,
            "seed": seed,
            "protocol": {
                "path": protocol.path,
                "sha256": protocol.sha256,
                "settings": protocol.settings(),
                "text": protocol.text,
            },
            "latin_squares": squares,
            "schedule": [t.to_dict() for t in schedule],
            "apparatus": {"rate": protocol.rate, "knobs": protocol.knobs, "pads": protocol.pads,
                          "gesture": protocol.gesture, **(apparatus or {})},
        }
        folder.mkdir(parents=True)
        with atomic_open(folder / SESSION_FILE, encoding="utf-8") as f:
            json.dump(info, f, indent=2)
            f.write("\n")
            f.flush()
            os.fsync(f.fileno())
        fsync_directory(folder)
        return cls(folder)

    @classmethod
    def resume(cls, protocol, participant, results, seed=None):
        """Reopen ``participant``'s unfinished session of ``protocol`` under ``results``."""
        check_participant(participant)
        participant_folder = Path(results) / protocol.study / participant
        folders = session_folders(participant_folder)
        if not folders:
            raise UserError(f"participant {participant!r} has no session to resume in {participant_folder}: "
                            "allowed is to start one without --resume")
        session = cls(folders[-1])
        stored = session.info["protocol"]["sha256"]
        if stored != protocol.sha256:
            session.close()
            raise UserError(f"{protocol.path}: differs from the protocol of session {session.folder} "
                            f"(sha256 {stored[:12]}...): allowed is the protocol file the session started with")
        if seed is not None and int(seed) != session.seed:
            session.close()
            raise UserError(f"--seed {seed}: session {session.folder} has seed {session.seed}: "
                            "allowed is to leave out --seed when resuming")
        if session.complete:
            session.close()
            raise UserError(f"session {session.folder} is already complete: nothing to resume")
        return session
