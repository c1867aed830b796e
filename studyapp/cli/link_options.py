"""The ``--latency``, ``--packet`` and ``--jitter`` options (samples) of the commands that simulate a device.

They put the simulated device behind a link (studyapp.model.link, issue 29):
a fixed round-trip latency, the sensor packets' length and a random extra
delay per packet, all 0 by default (the paper's loop). They count samples at
the command's ``--rate``, as ``live --device-latency`` / ``--device-packet``
and ``bench device --latency`` / ``--packet`` do (issue 41: one unit per
quantity on every command line; the console shows the samples with their ms
beside them). A value that is not a whole number from 0 to ``LINK_MAX`` worth
of samples is one ``ParameterError`` line naming the option; a fraction
(a time in seconds, as these options took before) says what it is in samples.
Plain argparse, so registering a command stays fast.
"""

OPTIONS = (
    ("latency", "round-trip latency of the device's link: the force computed from sample k acts from k + L"),
    ("packet", "the link's packet length: the device sends its samples in packets, and applies each packet's "
               "answer (the force from its newest sample) until the next one arrives; 0 or 1: every sample"),
    ("jitter", "the link's largest random extra delay per packet (uniform, never reordering)"),
)


def add(parser):
    for name, text in OPTIONS:
        parser.add_argument(f"--{name}", default="0", metavar="SAMPLES",
                            help=f"{text} (samples at --rate, a whole number up to 1 s worth; default 0)")


def samples(text, name, rate):
    """The option ``--name``'s whole number of samples from ``text``; one ``ParameterError`` line if it is none."""
    import math

    from studyapp.errors import ParameterError
    from studyapp.model.link import LINK_MAX

    largest = int(LINK_MAX * rate)
    allowed = f"allowed is a whole number of samples from 0 to {largest} ({LINK_MAX:g} s at {rate:g} Hz)"
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ParameterError(f"--{name} {text!r}: {allowed}") from None
    if not math.isfinite(value) or value != int(value):
        hint = f"; {value:g} s would be {value * rate:g}" if 0 < value <= LINK_MAX else ""
        raise ParameterError(f"--{name} {text}: {allowed}{hint}")
    if not 0 <= value <= largest:
        raise ParameterError(f"--{name} {text}: {allowed}")
    return int(value)


def spec(args, rate):
    """The ``LinkSpec`` (seconds) of the parsed options at ``rate`` Hz."""
    from studyapp.model.link import LinkSpec

    return LinkSpec(**{name: samples(getattr(args, name), name, rate) / rate for name, _ in OPTIONS})


def words(args):
    """The link's options for a canonical command line: only those that are not 0."""
    return "".join(f" --{name} {int(float(getattr(args, name)))}" for name, _ in OPTIONS
                   if float(getattr(args, name)))
