"""The session-info options of ``studyapp run`` and ``studyapp gui`` (experiment/session_info.py says what is allowed)."""


def add_session_info_options(parser):
    """``--experimenter``, ``--session-number``, ``--notes``, ``--order-row`` (also ``studyapp gui``'s)."""
    parser.add_argument("--experimenter", metavar="NAME", help="who runs the session (a short name)")
    parser.add_argument("--session-number", metavar="N", help="the lab's session number, 1 to 999")
    parser.add_argument("--notes", metavar="TEXT", help="notes on the session (up to 2000 characters)")
    parser.add_argument("--order-row", metavar="N",
                        help="the Latin-square order row, from 0 (default: from the participant's enrolment)")


def session_info_of(args):
    """The session-info options as ``Session.create``'s keyword arguments."""
    return {"experimenter": args.experimenter, "session_number": args.session_number, "notes": args.notes,
            "order_row": args.order_row}
