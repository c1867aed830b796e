"""A session: one participant's run of a protocol, kept on disk as it happens.

Layout (DESIGN.md "Results layout"):

    RESULTS/<study>/<participant>/<session-start>/session.json
    RESULTS/<study>/<participant>/<session-start>/events.jsonl

``session.json`` is written once, atomically, when the session is created:
the protocol (its text, validated settings and SHA-256), the app version, the
seed, the participant's enrolment index (counted among participants of the
same kind, real or simulated: ``enrolment``) and Latin-square rows, whether
the simulated participant plays (``simulated``), the order row
(``order_row``, ``order_rows``, ``order_row_source``), the schedule, the
apparatus (device, rate), and what the experimenter tells (``experimenter``,
``session_number``, ``notes``; ``session_info`` checks them, before anything
is written). ``device`` says what the participant held: ``{"kind":
"simulated", "latency_ms": 0}``, or ``{"kind": "link", "link": PATH_OR_URL,
"info": {...}}`` with the device's handshake as the console last had it
(link_device.LinkDevice.info: name, serial, protocol and firmware versions,
calibration, latency, measured round trip; null if none had come yet). Everything that happens afterwards is an
event in ``events.jsonl`` (see ``session_log``).

A trial is finished when its ``response`` event is on disk. ``resume`` reopens
the participant's session and continues at the first unfinished trial; the
schedule and the protocol come from session.json, so nothing is lost,
repeated or reordered. Creating a second session for a participant who
already has one is refused: resume it, or use another participant ID.

Participant IDs are pseudonyms (1 to 32 letters, digits, '_' or '-'); nothing
else about the participant is stored.

Data safety (docs/experiment.md "Data safety"):

- ``create`` and ``resume`` take the participant's lock (``session_lock``)
  before they read or write anything, and the session holds it until
  ``close``: a second program starting the same participant is refused with
  one line naming the holder, and writes nothing. ``create`` also holds the
  study's lock while it enrols, so two participants never get one index. A
  ``create`` that fails removes what it made, a lock file only while it holds
  that lock (never the winner's), and says that there is nothing to resume.
- The first event of ``events.jsonl`` (``session_created``) repeats the whole
  description. A ``session.json`` that is missing or damaged is rebuilt from it
  on resume (the damaged file is kept as ``session.json.damaged-<time>``);
  without it the session is refused with one line.
- Resuming a session whose every trial is answered writes its ``session_end``
  if a kill kept that from being written, and says it is complete.
- Folders and files get the modes of ``data_modes`` (private by default).
"""

import fcntl
import json
import os
import shutil
from datetime import datetime
from pathlib import Path

import numpy as np

from studyapp import __version__
from studyapp.io.atomic import atomic_open
from studyapp.errors import UserError
from studyapp.provenance import environment
from studyapp.experiment import records
from studyapp.experiment.data_modes import file_mode, make_folders
from studyapp.experiment.enrolment import apparatus_is_simulated, enrolment_index
from studyapp.experiment.folder_links import refuse_links
from studyapp.experiment.protocol import NAME_ALLOWED, NAME_PATTERN, parse_protocol
from studyapp.experiment.schedule import Trial, build_schedule
from studyapp.experiment.log_scan import written_twice
from studyapp.experiment.session_description import read_description, session_folders
from studyapp.experiment.session_files import EVENTS_FILE, FORMAT, LOCK_FILE, SESSION_FILE
from studyapp.experiment.session_info import (
    check_experimenter,
    check_notes,
    check_order_row,
    check_session_number,
    order_rows,
)
from studyapp.experiment.session_lock import ParticipantLock, StudyLock, remove_if_free
from studyapp.experiment.session_log import LogLock, LogWriteError, SessionLog, fsync_directory, read_events, read_log, wall_time
from studyapp.io.free_names import first_free
from studyapp.io.wav_header import repair_wav

CREATED = records.SESSION_CREATED
SIMULATED_DEVICE = {"kind": "simulated", "latency_ms": 0.0}  # session.json's ``device`` on the simulated device
SESSION_END = records.SESSION_END


def check_participant(participant):
    if not isinstance(participant, str) or not NAME_PATTERN.fullmatch(participant):
        raise UserError(f"participant ID {participant!r}: allowed is a pseudonym of {NAME_ALLOWED}")
    return participant


def _rebuild_description(folder, info):
    """Write session.json anew from ``info``, keeping a damaged one beside it; return the notes."""
    damaged = folder / SESSION_FILE
    notes = []
    try:
        if damaged.exists():
            stamp = datetime.now().strftime("%Y%m%dT%H%M%S")
            os.replace(damaged, damaged.with_name(f"{SESSION_FILE}.damaged-{stamp}"))
            notes.append(f"{damaged}: the damaged file is kept as {SESSION_FILE}.damaged-{stamp}")
        _write_description(folder, info)
    except OSError as exc:
        raise LogWriteError(f"{damaged}: cannot rebuild it ({exc.strerror or exc}): "
                            "allowed is to free disk space and try again") from None
    return notes + [f"{damaged}: rebuilt from {EVENTS_FILE}"]


def _write_description(folder, info):
    with atomic_open(folder / SESSION_FILE, encoding="utf-8", permissions=file_mode()) as f:
        json.dump(info, f, indent=2)
        f.write("\n")
        f.flush()
        os.fsync(f.fileno())
    fsync_directory(folder)


def default_seed(protocol_seed, participant_index):
    """The session seed when none is given: reproducible from the study seed and enrolment index."""
    return int(np.random.SeedSequence([protocol_seed, participant_index]).generate_state(1)[0])


class Session:
    """An open session folder: its stored description, schedule and event log.

    Opened by ``create`` or ``resume``, which hold the participant's lock; ``close`` releases it.
    """

    def __init__(self, folder, lock=None, log_lock=None):
        self.folder = Path(folder)
        self.lock = lock
        self._log_lock = log_lock  # the log's own lock (session_log.LogLock) when the opener took it first
        self.notes = []  # what opening it found or repaired, one line each, for the program to show
        try:
            self._open()
        except BaseException:
            if log_lock is not None and not hasattr(self, "log"):
                log_lock.release()
            self._release()
            raise

    def _open(self):
        self.info, notes = read_description(self.folder)
        if notes:
            notes += _rebuild_description(self.folder, self.info)
        self.notes.extend(notes)
        self.protocol = parse_protocol(self.info["protocol"]["text"], self.info["protocol"]["path"])
        self.schedule = [Trial.from_dict(d) for d in self.info["schedule"]]
        self.log = SessionLog(self.folder / EVENTS_FILE, self._log_lock)
        self.notes.extend(self.log.notes)

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
        if hasattr(self, "log"):
            self.log.close()
        self._release()

    def _release(self):
        if self.lock is not None:
            self.lock.release()

    @classmethod
    def create(cls, protocol, participant, results, seed=None, apparatus=None, experimenter=None,
               session_number=None, notes=None, order_row=None, device=None):
        """A new session of ``participant`` under ``results``; refused if they already have one.

        ``order_row`` None: the enrolment index decides it (``session_info``). ``device``: session.json's
        ``device`` (``kind`` simulated or link, a link's ``info``); None: the simulated device.
        """
        check_participant(participant)
        told = {"experimenter": check_experimenter(experimenter), "session_number": check_session_number(session_number),
                "notes": check_notes(notes)}
        order_row = check_order_row(protocol, order_row)
        study_folder = Path(results) / protocol.study
        participant_folder = study_folder / participant
        refuse_links(results, participant_folder)  # read-only, before anything is made or written
        if not lock_taken(participant_folder):  # read-only, before the lock: a refusal changes nothing
            _refuse_existing(participant_folder, participant)
        try:
            made = make_folders(participant_folder)
        except OSError as exc:
            raise UserError(f"{participant_folder}: cannot create the folder ({exc.strerror or exc}): "
                            "allowed is a writable results folder (--results)") from None
        folder = None
        try:
            lock = ParticipantLock(participant_folder, participant)
        except BaseException:
            _remove_made(made)  # the winner's lock stays: only a free lock file is removed
            raise
        try:
            _refuse_existing(participant_folder, participant)  # again under the lock: one may have begun meanwhile
            with StudyLock(study_folder):
                folder, info = cls._describe(protocol, participant, study_folder, participant_folder,
                                             seed, apparatus, order_row)
                info.update(told)
                info["device"] = dict(device if device is not None else SIMULATED_DEVICE)
                make_folders(folder)
                _write_description(folder, info)
            session = cls(folder, lock)
            try:
                session.log.append(records.session_created(info))
            except BaseException:
                session.log.close()
                raise
            return session
        except BaseException as failure:
            if folder is not None:
                shutil.rmtree(folder, ignore_errors=True)  # only just made: it holds no response yet
            _remove_made(made, lock)
            lock.release()
            if isinstance(failure, (OSError, LogWriteError)):
                left = folder is not None and folder.exists()
                raise _not_created(folder or participant_folder, left, failure) from None
            raise

    @staticmethod
    def _describe(protocol, participant, study_folder, participant_folder, seed, apparatus, order_row):
        """(the new session's folder, its description): enrolment index, seed, order row, schedule, protocol."""
        simulated = apparatus_is_simulated(apparatus)
        index = enrolment_index(study_folder, participant, simulated)  # counted per kind (enrolment.py)
        seed = default_seed(protocol.seed, index) if seed is None else int(seed)
        rows = order_rows(protocol)
        source = "enrolment" if order_row is None else "set"
        order_row = index % rows if order_row is None else order_row  # the same orders as the index itself
        schedule, squares = build_schedule(protocol, index, order_row=order_row)
        started = datetime.now().astimezone()
        folder = first_free(participant_folder / started.strftime("%Y-%m-%dT%H-%M-%S"))
        info = {
            "format": FORMAT,
            "study": protocol.study,
            "participant": participant,
            "participant_index": index,
            "simulated": simulated,
            "session": folder.name,
            "started": wall_time(),
            "app_version": __version__,
            "environment": environment(),
            "seed": seed,
            "protocol": {
                "path": protocol.path,
                "sha256": protocol.sha256,
                "settings": protocol.settings(),
                "text": protocol.text,
            },
            "latin_squares": squares,
            "order_row": order_row,
            "order_rows": rows,
            "order_row_source": source,
            "schedule": [t.to_dict() for t in schedule],
            "apparatus": {"rate": protocol.rate, "knobs": protocol.knobs, "pads": protocol.pads,
                          "gesture": protocol.gesture, **(apparatus or {})},
        }
        return folder, info

    @classmethod
    def resume(cls, protocol, participant, results, seed=None, order_row=None, **told):
        """Reopen ``participant``'s unfinished session of ``protocol`` under ``results``.

        Everything is checked, read-only, before the log is opened (which may repair it).
        ``order_row`` may only repeat the stored one; the experimenter's fields (``told``)
        belong to the session's start and are refused.
        """
        check_participant(participant)
        given = [key for key, value in told.items() if value not in (None, "")]
        if given:
            raise UserError(f"{given[0].replace('_', ' ')}: set when a session starts, not when it is resumed: "
                            "allowed is to leave it empty with resume")
        participant_folder = Path(results) / protocol.study / participant
        refuse_links(results, participant_folder)
        if not session_folders(participant_folder):
            raise UserError(f"participant {participant!r} has no session to resume in {participant_folder}: "
                            "allowed is to start one without --resume")
        refuse_links(results, session_folders(participant_folder)[-1])
        if not lock_taken(participant_folder):  # read-only, before the lock: a refusal changes nothing
            read_description(session_folders(participant_folder)[-1])
        lock = ParticipantLock(participant_folder, participant)
        log_lock = None
        try:
            folder = session_folders(participant_folder)[-1]
            # the log's own lock before anything is read: a writer that got past a deleted .lock is refused here
            if os.path.lexists(folder / EVENTS_FILE):  # a missing log is created (and locked) only once checked
                log_lock = LogLock(folder / EVENTS_FILE)
            log = read_log(folder / EVENTS_FILE)
            info, rebuild = read_description(folder, log)
            _check_owner(info, participant, participant_folder, folder)
            stored = info["protocol"]["sha256"]
            if stored != protocol.sha256:
                raise UserError(f"{protocol.path}: differs from the protocol of session {folder} "
                                f"(sha256 {stored[:12]}...): allowed is the protocol file the session started with")
            if seed is not None and int(seed) != info["seed"]:
                raise UserError(f"--seed {seed}: session {folder} has seed {info['seed']}: "
                                "allowed is to leave out --seed when resuming")
            if order_row is not None and check_order_row(protocol, order_row) != info.get("order_row"):
                raise UserError(f"order row {order_row}: session {folder} has order row {info.get('order_row')}: "
                                "allowed is to leave it out when resuming")
            twice = written_twice(log)
            if twice:  # export skips such a log whole: what is added to it would be lost too
                raise UserError(f"{folder / EVENTS_FILE}: {twice}: two programs wrote this log at once, so it "
                                "cannot be continued (export skips it): allowed is to run the participant again "
                                "under another participant ID")
            events = log.events
            done = {e.get("step") for e in events if e.get("type") == "response"}
            heard = repair_recordings(folder)  # under the lock: no engine of this session writes them now
            if all(t["step"] in done for t in info["schedule"]):
                # resuming is the way to repair a session, a complete one too: its session.json, its
                # recordings' headers, and the session_end a kill after the last response kept from being written
                repaired = [f"{len(heard)} recording header(s) repaired"] if heard else []
                if rebuild:
                    _rebuild_description(folder, info)
                    repaired.append("its session.json rebuilt from events.jsonl")
                if not any(e.get("type") == SESSION_END for e in events):
                    with SessionLog(folder / EVENTS_FILE, log_lock) as log:
                        log_lock = None  # the log owns it now
                        log.append(records.session_end(recovered=True))
                    repaired.append(f"its missing {SESSION_END} event written")
                said = f" ({'; '.join(repaired)})" if repaired else ""
                raise UserError(f"session {folder} is already complete{said}: nothing to resume")
        except BaseException:
            if log_lock is not None:
                log_lock.release()
            lock.release()
            raise
        session = cls(folder, lock, log_lock)
        session.notes.extend(heard)
        return session


def _check_owner(info, participant, participant_folder, folder):
    """Refuse to continue a session that is not ``participant``'s own: a participant folder copied under another
    ID (its log names the session's participant; a folder linked is refused before, by ``refuse_links``)."""
    if info["participant"] != participant:
        raise UserError(f"{folder}: holds a session of participant {info['participant']!r} (its log says so), not "
                        f"of {participant!r}: a participant folder copied or renamed is not resumed: allowed is "
                        f"to resume {info['participant']!r} in its own folder, or to start {participant!r} anew")


def repair_recordings(folder):
    """Make the headers of the session's recordings (``audio*.wav``) match their sizes (``io.wav_header``:
    a kill between a write and its header's update); one line per file repaired."""
    return [line for path in sorted(Path(folder).glob("audio*.wav")) if (line := repair_wav(path)) is not None]


def lock_taken(participant_folder):
    """True when another open of the participant's lock holds it (its refusal, naming the holder, comes
    first); tested on a descriptor of our own that creates and writes nothing."""
    try:
        fd = os.open(Path(participant_folder) / LOCK_FILE, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # dropped when fd closes
        return False
    except OSError:
        return True
    finally:
        os.close(fd)


def _refuse_existing(participant_folder, participant):
    existing = session_folders(participant_folder)
    if existing:
        raise UserError(f"participant {participant!r} already has a session in {existing[-1]}: "
                        "allowed is --resume to continue it, or another participant ID")


def _not_created(folder, left, failure):
    """What is true after a failed create (a full disk): its folder removed (unless ``left``), so a start
    again, not a resume."""
    reason = failure.reason if isinstance(failure, LogWriteError) else failure.strerror or failure
    if left:
        return UserError(f"{folder}: cannot create the session ({reason}), and its partial folder could not be "
                         "removed: allowed is to remove that folder, free disk space and start the session again")
    return UserError(f"{folder}: cannot create the session ({reason}): nothing was kept, so there is nothing to "
                     "resume: allowed is a writable results folder with free space, then start the session again "
                     "(without --resume)")


def _remove_made(made, lock=None):
    """Remove the folders ``make_folders`` made (newest first) while nothing but a free lock is in them.

    The participant's lock file goes only if ``lock`` (ours) holds it; another folder's
    only if no one holds it (``remove_if_free``): never a lock another program holds."""
    for folder in reversed(made):
        try:
            if lock is not None and lock.held and lock.path.parent == folder:
                lock.release(remove=True)
            elif not remove_if_free(folder):
                return
            folder.rmdir()
        except OSError:
            return
