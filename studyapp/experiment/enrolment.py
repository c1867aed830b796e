"""Who is enrolled in a study, and which enrolment index (so which Latin-square order row) a newcomer gets.

A session is *simulated* when the simulated participant played it: its
session.json says ``"simulated": true`` (or, for a session stored before that
key existed, ``apparatus.participant == "simulated"``, which the console and
``studyapp run --simulated-participant --headless`` have always written).

The rule for order rows (docs/experiment.md "Order rows"): real and simulated
participants are counted apart. A newcomer's enrolment index is the number of
participants *of the same kind* already enrolled in the study, so the k-th real
participant (from 0) gets order row k mod L whatever simulated runs came
before or between, and simulated runs cycle through the rows on their own
count. A demo or an in-silico pilot in the study's results folder therefore
never uses up a real participant's order, and the balance of the Latin squares
over real participants holds. A participant whose sessions cannot be read
counts as real: a row may then be skipped, but no real participant's row is
ever given twice.
"""

from pathlib import Path

from studyapp.errors import UserError
from studyapp.experiment.session_description import read_description, session_folders


def is_simulated(info):
    """True when the session described by ``info`` (session.json) was played by the simulated participant."""
    if not isinstance(info, dict):
        return False
    if "simulated" in info:
        return info["simulated"] is True
    apparatus = info.get("apparatus")
    return isinstance(apparatus, dict) and apparatus.get("participant") == "simulated"


def apparatus_is_simulated(apparatus):
    """True when a new session's ``apparatus`` says the simulated participant plays it."""
    return isinstance(apparatus, dict) and apparatus.get("participant") == "simulated"


def first_sessions(study_folder):
    """(participant, session.json or None when unreadable) of each participant with a session under ``study_folder``."""
    folder = Path(study_folder)
    if not folder.is_dir():
        return
    for participant_folder in sorted(p for p in folder.iterdir() if p.is_dir()):
        sessions = session_folders(participant_folder)
        if not sessions:
            continue
        try:
            info, _ = read_description(sessions[0])
        except UserError:
            info = None
        yield participant_folder.name, info


def enrolled(study_folder):
    """{participant: simulated?} of every participant with a session under ``study_folder``.

    An unreadable session counts as real (module docstring).
    """
    return {name: is_simulated(info) for name, info in first_sessions(study_folder)}


def enrolment_index(study_folder, participant, simulated):
    """The enrolment index of a new ``participant``: participants of the same kind enrolled before them."""
    return sum(1 for name, kind in enrolled(study_folder).items() if name != participant and kind == bool(simulated))


def check_same_player(results, study, participant, simulated):
    """Refuse (``UserError``) to resume ``participant``'s latest session with the other kind of player.

    A real participant's log is never continued by the simulated participant, nor a simulated one's by a
    person (its order row was counted among the simulated): read only, before anything opens the log.
    """
    sessions = session_folders(Path(results) / study / participant)
    if not sessions:
        return
    try:
        info, _ = read_description(sessions[-1])
    except UserError:
        return  # resume itself says what is wrong with it
    stored = is_simulated(info)
    if stored == bool(simulated):
        return
    if stored:
        raise UserError(f"participant {participant!r}: session {sessions[-1]} was played by the simulated "
                        "participant: allowed is to resume it with --simulated-participant")
    raise UserError(f"participant {participant!r}: session {sessions[-1]} is a real participant's: allowed is to "
                    "resume it without --simulated-participant (a machine never continues a person's log)")
