"""The link's force on closed forms (studyapp.model.link, issue 29 item 1): delay, packets, loss, jitter."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.model.link import LINK_MAX, Link, LinkSpec, applied

RATE = 5000.0


def link(seed=0, **times):
    return Link(LinkSpec(**times), RATE, np.random.SeedSequence(seed).spawn(2))


def commands(n):
    """Distinct, increasing commands: the applied value names the sample whose command it is (F[k] = k + 1)."""
    return np.arange(1.0, n + 1.0)


def test_an_ideal_link_applies_each_command_at_once():
    f = np.random.default_rng(0).standard_normal(1000)
    assert np.array_equal(applied(link(), f), f)


@pytest.mark.parametrize("samples", [1, 2, 5, 13])
def test_a_fixed_latency_shifts_the_commands_by_L_samples_with_0_before(samples):
    f = np.random.default_rng(samples).standard_normal(500)
    u = applied(link(latency=samples / RATE), f)
    assert np.array_equal(u[:samples], np.zeros(samples))
    assert np.array_equal(u[samples:], f[:-samples])


def test_latency_rounds_to_whole_samples():
    assert LinkSpec(latency=0.00029).samples(RATE) == (1, 1, 0)
    assert LinkSpec(latency=0.0002, packet=0.001, jitter=0.0004).samples(RATE) == (1, 5, 2)
    assert LinkSpec(packet=0.00001).samples(RATE) == (0, 1, 0)  # below a sample: every sample


@pytest.mark.parametrize("latency", [0, 3])
def test_a_packet_holds_its_newest_samples_command_until_the_next_arrives(latency):
    """P = 5: packet p's newest sample e = 5p + 4; its command acts over [e + L, e + L + 5)."""
    n, p = 40, 5
    u = applied(link(latency=latency / RATE, packet=p / RATE), commands(n))
    expected = np.zeros(n)
    for e in range(p - 1, n, p):
        expected[e + latency:] = e + 1
    assert np.array_equal(u, expected)
    # the command in effect is L .. L + P - 1 samples old: L + (P - 1) / 2 on average over whole packets
    j = np.arange(p - 1 + latency, n)
    ages = j - (u[j] - 1)
    assert (ages.min(), ages.max()) == (latency, latency + p - 1)
    assert ages[:6 * p].mean() == latency + (p - 1) / 2


def test_a_lost_frame_holds_the_last_force_received():
    n = 20000
    f = commands(n)
    u = applied(link(seed=3, latency=2 / RATE, loss=0.3), f)
    fresh = u[2:] == f[:-2]
    held = u[3:] == u[2:-1]
    assert np.all(fresh[1:] | held)  # each applied force is the newest command or the one before held
    assert np.mean(~fresh) == pytest.approx(0.3, abs=0.02)


def test_jitter_never_reorders_and_stays_within_its_bound():
    """Commands arrive L .. L + J samples late; the device never goes back to an older one."""
    n, lat, jit = 20000, 2, 6
    f = commands(n)
    u = applied(link(seed=7, latency=lat / RATE, jitter=jit / RATE), f)
    assert np.all(np.diff(u) >= 0)  # never an older command after a newer one
    j = np.arange(n)
    sent = u - 1  # the sample whose command is in effect (-1: none yet)
    assert np.all(sent[u > 0] <= j[u > 0] - lat)  # never before its latency
    assert np.all(sent[lat + jit:] >= j[lat + jit:] - lat - jit)  # never staler than L + J
    ages = j[u > 0] - sent[u > 0]
    assert ages.min() == lat and ages.max() == lat + jit  # both ends of the jitter's range occur


def test_the_draws_do_not_depend_on_how_the_run_is_cut():
    spec = dict(latency=1 / RATE, packet=3 / RATE, jitter=4 / RATE, loss=0.2)
    whole = link(seed=5, **spec).delays(1000)
    cut = link(seed=5, **spec)
    parts = np.concatenate([cut.delays(n) for n in (1, 7, 300, 2, 690)])
    assert np.array_equal(whole, parts)
    assert not np.array_equal(whole, link(seed=6, **spec).delays(1000))  # seeded
    # one delay per packet, at its newest sample: L + (0 .. J), or -1 when lost
    ends = whole[2::3]
    assert np.all(np.delete(whole, np.s_[2::3]) == -1)
    assert set(np.unique(ends)) <= {-1.0, 1.0, 2.0, 3.0, 4.0, 5.0}


@pytest.mark.parametrize("field, value", [("latency", -0.001), ("packet", float("nan")), ("jitter", LINK_MAX * 2),
                                          ("latency", "soon"), ("jitter", float("inf"))])
def test_bad_link_times_are_refused_naming_the_field(field, value):
    with pytest.raises(ParameterError, match=f"^{field} .*allowed is a number of seconds from 0 to 1$"):
        LinkSpec(**{field: value})


@pytest.mark.parametrize("loss", [-0.1, 1.0, float("nan")])
def test_bad_loss_is_refused(loss):
    with pytest.raises(ParameterError, match="^loss "):
        LinkSpec(loss=loss)
