"""The ``--delay normalised|paper`` option of every command that measures delay (``evaluation/metric.py``).

Plain argparse, so registering a command stays fast; the names are the
metric's ``METHODS`` (a test holds them equal).
"""

METHODS = ("normalised", "paper")


def add(parser):
    parser.add_argument(
        "--delay", choices=METHODS, default=METHODS[0],
        help="delay D: 'normalised' (the default), the peak of the cross-correlation normalised over the "
             "overlap, lags -max-lag..max-lag (a lead reads negative); 'paper', eq. 22 as printed, "
             "unnormalised, lags 0..max-lag")
