"""The ``--latency``, ``--packet`` and ``--jitter`` options (seconds) of the commands that simulate a device.

They put the simulated device behind a link (studyapp.model.link, issue 29):
a fixed round-trip latency, the sensor packets' length and a random extra
delay per packet, all 0 by default (the paper's loop). Plain argparse, so
registering a command stays fast; each value is checked by the link's own
``check_time`` (finite, 0 to 1 s) when the command runs.
"""

OPTIONS = (
    ("latency", "round-trip latency of the device's link: the force computed from sample k acts from k + L"),
    ("packet", "the link's packet length: the device sends its samples in packets, and applies each packet's "
               "answer (the force from its newest sample) until the next one arrives; 0: every sample"),
    ("jitter", "the link's largest random extra delay per packet (uniform, never reordering)"),
)


def add(parser):
    for name, text in OPTIONS:
        parser.add_argument(f"--{name}", type=float, default=0.0, metavar="SECONDS",
                            help=f"{text} (seconds, rounded to samples; 0 to 1; default 0)")


def spec(args):
    """The ``LinkSpec`` of the parsed options; one ``ParameterError`` line naming the option if one is out of range."""
    from studyapp.model.link import LinkSpec, check_time

    return LinkSpec(**{name: check_time(getattr(args, name), f"--{name}") for name, _ in OPTIONS})


def words(args):
    """The link's options for a canonical command line: only those that are not 0."""
    return "".join(f" --{name} {getattr(args, name):g}" for name, _ in OPTIONS if getattr(args, name))
