"""``studyapp notes PATH [--add TEXT] [-o FILE.csv]``: list the experimenter's notes, or add one after a session.

Without ``--add``: every ``note`` event under PATH (a results folder, or any
folder inside it) as a table on stdout (study, participant, session, wall
time, step, task, text), or as CSV with ``-o``. With ``--add TEXT``: PATH is
a session folder (or a participant folder: their latest session) and TEXT
is appended to its events.jsonl as a note with the time now
(``studyapp.experiment.session_notes``); refused while a session of that
participant runs in another program.
"""


def register(sub):
    parser = sub.add_parser("notes", help="list the experimenter's notes, or add one to a session after it ran")
    parser.add_argument("path", metavar="PATH", help="results folder (to list), or a session folder (with --add)")
    parser.add_argument("--add", metavar="TEXT", help="append TEXT as a note to the session in PATH")
    parser.add_argument("-o", "--output", metavar="FILE.csv", help="write the list as CSV")
    parser.set_defaults(func=run)


def run(args):
    import sys

    import pandas as pd

    from studyapp.io.atomic import atomic_open
    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.experiment.session_notes import add_note, list_notes, note_event, session_folder_of

    if args.add is not None:
        if args.output is not None:
            raise UserError("-o: allowed only when listing notes, not with --add")
        note_event(args.add)  # the text first: a bad note touches no session
        folder = session_folder_of(args.path)
        record = add_note(folder, args.add)
        print(f"studyapp notes: note logged in {folder} at {record['wall']}", file=sys.stderr)
        return 0
    if args.output is not None:
        output_paths.check_file(args.output)
    frame = list_notes(args.path)
    if args.output is not None:
        with atomic_open(args.output, newline="", encoding="utf-8") as f:
            frame.to_csv(f, index=False)
        print(f"studyapp notes: {len(frame)} note(s) -> {args.output}", file=sys.stderr)
        return 0
    for row in frame.itertuples(index=False):
        step = "" if pd.isna(row.step) else f" step {int(row.step) + 1}"
        text = str(row.text).replace("\n", "\n    ")
        print(f"{row.wall}  {row.participant} {row.session}{step}: {text}")
    print(f"studyapp notes: {len(frame)} note(s)", file=sys.stderr)
    return 0
