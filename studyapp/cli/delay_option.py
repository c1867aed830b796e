"""The ``--delay normalised|paper`` option of every command that measures delay (``evaluation/metric.py``).

Plain argparse, so registering a command stays fast; the names are the
metric's ``METHODS`` (a test holds them equal).
"""

METHODS = ("normalised", "paper")
MAX_LAG_LIMIT_S = 1.0  # s: the largest --max-lag (the paper's delays are milliseconds; 1e308 overflowed)


def check_max_lag(seconds):
    """``--max-lag`` in (0, ``MAX_LAG_LIMIT_S``] s, else one ``UserError`` line."""
    from studyapp.errors import UserError

    if not 0 < seconds <= MAX_LAG_LIMIT_S:
        raise UserError(f"--max-lag {seconds:g}: allowed is a positive number of seconds up to {MAX_LAG_LIMIT_S:g}")


def add(parser):
    parser.add_argument(
        "--delay", choices=METHODS, default=METHODS[0],
        help="delay D: 'normalised' (the default), the peak of the cross-correlation normalised over the "
             "overlap, lags -max-lag..max-lag (a lead reads negative); 'paper', eq. 22 as printed, "
             "unnormalised, lags 0..max-lag")
