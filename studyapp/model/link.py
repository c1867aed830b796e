"""The link between the host and a device: latency, packets, jitter and frame loss (issue 29, item 1).

The paper's loop (Fig. 1, Sec. 2) has a one-step delay: the force F[k]
computed from the sensors at sample k acts over [k, k+1], so the position
sampled at k+1 is the first to feel it. A real rig adds its link: the host
receives the sensors late and its command travels back. This module models
that link on the device's sample clock (the device owns the clock; the host
answers it), with every time rounded to whole samples at the loop's rate:

    L = round(latency * rate)       the fixed round-trip latency (samples)
    P = max(1, round(packet * rate)) the packet: the device sends its sensor
                                     samples P at a time (packet = 0: P = 1)
    J = round(jitter * rate)        the largest random extra delay per packet
    loss                            the probability that a packet's command is lost

Packet p holds the sensor samples pP .. pP + P - 1 and leaves the device
after its newest sample e_p = pP + P - 1. The host runs its controller on
every sample (the estimators and the string need each one) and answers the
packet with one command: the force computed from the packet's newest sample,
F[e_p]. That command arrives at the device at

    a_p = e_p + L + d_p,     d_p uniform on the integers 0 .. J, drawn per packet,

and is lost with probability ``loss``. The device applies, over the step
[j, j+1], the newest command that has arrived,

    u[j] = F[e_q],   q = max{p : a_p <= j, packet p not lost},

and 0 N before any has arrived. So the device never goes back to an older
command (a late packet overtaken by a newer one is dropped: jitter never
reorders), and after a lost packet it holds the last force it received.

Special cases. P = 1, J = 0, no loss: u[j] = F[j - L], a pure delay of L
samples (L = 0 is the paper's loop, bit for bit: u[j] = F[j]); an impulse in
F at sample k moves the position first at sample k + L + 1. P > 1, L = 0:
a zero-order hold of the newest sample's force over each packet; sample j of
a packet sees its force (j - e_p) samples late, 0 .. P - 1, (P - 1) / 2 on
average. (The other way to answer a packet, one force per sample applied on
the device at its sample's time plus a packet, is a pure delay of P - 1
samples: ``latency = (P - 1) / rate`` with P = 1 models it; docs/devices.md
compares the two with the measured figures of issue 29.)

Computation, O(1) per sample. The link's state holds the sample counter j,
the force in effect and the send time of its command, and a ring of M =
L + J + 1 arrival slots (a command sent at j arrives in j .. j + L + J):
slot a mod M holds the newest command due at a. At sample j, ``step``
first puts the command sent now (if the host sends one) in its arrival slot,
then takes the command due at j if it is newer than the one in effect, and
empties the slot. The random draws (d_p, lost) are made in Python, one per
packet in packet order from two seeded generators, so the stream does not
depend on how the run is cut into blocks or samples; ``delays(n)`` gives the
kernel each sample's delay (L + d_p at a packet's newest sample, -1 when
nothing is sent or the packet is lost).
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.errors import ParameterError

LINK_MAX = 1.0  # s: the largest latency, packet and jitter (a rig's link is milliseconds)
NAMES = ("latency", "packet", "jitter")  # the link's times (s), the keys of the outputs that record them

# state: the sample counter, the force in effect, the send time of its command (-1: none yet), the ring's size M,
# then M arrival slots' send times (-1: empty) and M forces
LS_SAMPLE, LS_FORCE, LS_SENT, LS_SLOTS = range(4)
LS_RING = 4


def check_time(seconds, label):
    """A link time in seconds, finite and in [0, LINK_MAX]; else one ``ParameterError`` line naming ``label``."""
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = float("nan")
    if not 0.0 <= value <= LINK_MAX:
        raise ParameterError(f"{label} {seconds!r}: allowed is a number of seconds from 0 to {LINK_MAX:g}")
    return value


def check_loss(p, label="loss"):
    try:
        value = float(p)
    except (TypeError, ValueError):
        value = float("nan")
    if not 0.0 <= value < 1.0:
        raise ParameterError(f"{label} {p!r}: allowed is a probability from 0 up to (not including) 1")
    return value


@dataclass(frozen=True)
class LinkSpec:
    """A link: ``latency``, ``packet`` and ``jitter`` in seconds, ``loss`` a probability per packet (0: none)."""

    latency: float = 0.0
    packet: float = 0.0
    jitter: float = 0.0
    loss: float = 0.0

    def __post_init__(self):
        for name in NAMES:
            object.__setattr__(self, name, check_time(getattr(self, name), name))
        object.__setattr__(self, "loss", check_loss(self.loss))

    def samples(self, rate):
        """(L, P, J): latency, packet and largest jitter in samples at ``rate`` Hz (the module's rounding)."""
        rate = float(rate)
        return (int(round(self.latency * rate)), max(1, int(round(self.packet * rate))),
                int(round(self.jitter * rate)))

    def describe(self, rate):
        """What a recording's metadata and the breakdown outputs say of the link (seconds and samples)."""
        latency, packet, jitter = self.samples(rate)
        return {"latency": self.latency, "packet": self.packet, "jitter": self.jitter, "loss": self.loss,
                "latency_samples": latency, "packet_samples": packet, "jitter_samples": jitter}


IDEAL = LinkSpec()


class Link:
    """The link's state and its seeded draws, for a device at ``rate`` Hz; ``streams``: two SeedSequences.

    ``latency_samples``, ``packet_samples``, ``jitter_samples``: L, P and J of the module docstring.
    """

    def __init__(self, spec, rate, streams):
        self.spec = spec
        self.latency_samples, self.packet_samples, self.jitter_samples = spec.samples(rate)
        slots = self.latency_samples + self.jitter_samples + 1
        self.state = np.full(LS_RING + 2 * slots, -1.0)
        self.state[LS_SAMPLE] = 0.0
        self.state[LS_FORCE] = 0.0
        self.state[LS_SLOTS] = slots
        self.state[LS_RING + slots:] = 0.0
        self._rng_jitter, self._rng_loss = (np.random.default_rng(s) for s in streams)
        self._sample = 0
        # every sample sent and none drawn: each sample's delay is L (the per-sample path's common case)
        self._fixed = self.packet_samples == 1 and self.jitter_samples == 0 and spec.loss == 0.0

    def delays(self, n):
        """The next ``n`` samples' delays: L + d_p at a packet's newest sample (-1 if lost), else -1."""
        first = self._sample
        self._sample += n
        if self._fixed:
            return np.full(n, float(self.latency_samples))
        out = np.full(n, -1.0)
        p = self.packet_samples
        # the packets' newest samples: (j + 1) % P == 0
        ends = np.arange((first + p) // p * p - 1, first + n, p) - first
        if ends.size == 0:
            return out
        delay = np.full(ends.size, float(self.latency_samples))
        if self.jitter_samples > 0:
            delay += np.floor(self._rng_jitter.random(ends.size) * (self.jitter_samples + 1))
        if self.spec.loss > 0.0:
            delay[self._rng_loss.random(ends.size) < self.spec.loss] = -1.0
        out[ends] = delay
        return out


@njit(cache=True, inline="always")
def step(ls, f, delay):
    """The force (N) the device applies over the current step; ``f`` the host's command now, sent if delay >= 0."""
    j = ls[LS_SAMPLE]
    slots = int(ls[LS_SLOTS])
    if delay >= 0.0:
        slot = LS_RING + int(j + delay) % slots
        ls[slot] = j
        ls[slot + slots] = f
    slot = LS_RING + int(j) % slots
    if ls[slot] > ls[LS_SENT]:
        ls[LS_SENT] = ls[slot]
        ls[LS_FORCE] = ls[slot + slots]
    ls[slot] = -1.0
    ls[LS_SAMPLE] = j + 1.0
    return ls[LS_FORCE]


@njit(cache=True)
def _apply(ls, forces, delays, out):
    for k in range(forces.shape[0]):
        out[k] = step(ls, forces[k], delays[k])


def applied(link, forces):
    """The forces the device applies for the host's commands ``forces`` (one per sample), through ``link``."""
    forces = np.ascontiguousarray(forces, dtype=np.float64)
    out = np.empty_like(forces)
    _apply(link.state, forces, link.delays(forces.shape[0]), out)
    return out

