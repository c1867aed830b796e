"""Shared-memory rings and the status block: contents, wrap-around, and no torn reads under a live writer."""

import multiprocessing as mp
import time

import numpy as np
import pytest

from studyapp.engine.event_ring import EventRing
from studyapp.engine.events import Notice
from studyapp.engine.ring import Ring
from studyapp.engine.status import NUMBERS, StatusBlock


def test_ring_round_trip_across_the_wrap():
    ring = Ring.create(["a", "b"], capacity=10)
    try:
        got = []
        position = 0
        for start in range(0, 37, 7):
            n = np.arange(start, start + 7, dtype=float)
            ring.write({"a": n, "b": -n})
            data, first, end = ring.read_since(position)
            assert first == position and end == start + 7
            np.testing.assert_array_equal(data[0], np.arange(first, end))
            np.testing.assert_array_equal(data[1], -np.arange(first, end))
            got.append(data[0])
            position = end
        np.testing.assert_array_equal(np.concatenate(got), np.arange(42))
        latest, end = ring.read_latest(4)
        np.testing.assert_array_equal(latest[0], np.arange(38, 42))
        assert end == ring.committed == 42
    finally:
        ring.close()


def test_a_staged_block_is_unread_until_committed_and_withhold_zeroes_only_it_across_the_wrap():
    ring = Ring.create(["force", "force_scale", "t"], capacity=10)
    try:
        assert ring.withhold(["force"]) == 0  # nothing staged: nothing zeroed
        ring.write({"force": np.full(7, 2.0), "force_scale": np.ones(7), "t": np.arange(7.0)})
        ring.stage({"force": np.full(6, 3.0), "force_scale": np.ones(6), "t": np.arange(7.0, 13.0)})
        data, _, end = ring.read_since(0)
        assert end == ring.committed == 7 and np.all(data[0] == 2.0)
        assert ring.withhold(["force", "force_scale"]) == 6
        ring.commit()
        data, first, end = ring.read_since(7)
        assert (first, end) == (7, 13)
        np.testing.assert_array_equal(data[0], 0.0)
        np.testing.assert_array_equal(data[1], 0.0)
        np.testing.assert_array_equal(data[2], np.arange(7.0, 13.0))  # the other channels stand
        np.testing.assert_array_equal(ring.read_latest(10)[0][0][:4], 2.0)  # committed samples untouched
        assert ring.withhold(["force"]) == 0
    finally:
        ring.close()


def test_ring_reader_that_fell_behind_is_told_what_it_lost():
    ring = Ring.create(["a"], capacity=8)
    try:
        ring.write(np.arange(30, dtype=float)[None, :])
        data, first, end = ring.read_since(3)
        assert (first, end) == (22, 30)
        np.testing.assert_array_equal(data[0], np.arange(22, 30))
    finally:
        ring.close()


def test_ring_block_larger_than_capacity_keeps_the_newest():
    ring = Ring.create(["a"], capacity=5)
    try:
        ring.write(np.arange(12, dtype=float)[None, :])
        data, end = ring.read_latest(5)
        assert end == 12
        np.testing.assert_array_equal(data[0], np.arange(7, 12))
    finally:
        ring.close()


def _ring_writer(spec, seconds):
    ring = Ring.attach(spec)
    n = 0
    stop = time.monotonic() + seconds
    rng = np.random.default_rng(1)
    while time.monotonic() < stop:
        m = int(rng.integers(1, 40))
        samples = np.arange(n, n + m, dtype=float)
        ring.write(np.stack([samples, 2 * samples, 3 * samples]))
        n += m
    ring.close()


def _status_writer(name, seconds):
    status = StatusBlock.attach(name)
    k = 0
    stop = time.monotonic() + seconds
    while time.monotonic() < stop:
        k += 1
        status.values[:] = k
        status.set(state="running", source=f"S{k}", fault=f"F{k}")
        status.values[NUMBERS.index("state")] = k % 5
        status.publish(texts=True)
    status.close()


def test_ring_reads_are_never_torn_under_a_writer_in_another_process():
    # A small ring makes the writer lap readers often: every lap is a chance to tear.
    ring = Ring.create(["n", "2n", "3n"], capacity=64)
    proc = mp.get_context("spawn").Process(target=_ring_writer, args=(ring.spec, 1.5))
    proc.start()
    try:
        reads = 0
        deadline = time.monotonic() + 30
        while ring.committed == 0 and time.monotonic() < deadline:
            time.sleep(0.001)
        while proc.is_alive():
            data, end = ring.read_latest(48)
            if data.shape[1] == 0:
                continue
            expected = np.arange(end - data.shape[1], end, dtype=float)
            np.testing.assert_array_equal(data[0], expected)
            np.testing.assert_array_equal(data[1], 2 * expected)
            np.testing.assert_array_equal(data[2], 3 * expected)
            reads += 1
        assert reads > 100
    finally:
        proc.join(10)
        ring.close()


def test_status_snapshots_are_never_torn():
    status = StatusBlock.create()
    proc = mp.get_context("spawn").Process(target=_status_writer, args=(status.name, 1.5))
    proc.start()
    try:
        snapshots = 0
        deadline = time.monotonic() + 30
        while status.read()["blocks"] == 0 and time.monotonic() < deadline:
            time.sleep(0.001)
        while proc.is_alive():
            snap = status.read()
            k = snap["blocks"]
            assert snap["samples"] == k and snap["fmax"] == k and snap["heartbeat"] == k
            assert snap["source"] == f"S{k}" and snap["fault"] == f"F{k}"
            snapshots += 1
        assert snapshots > 100
    finally:
        proc.join(10)
        status.close()


def test_status_force_enable_word_is_shared():
    status = StatusBlock.create()
    other = StatusBlock.attach(status.name)
    try:
        assert other.force_enable
        status.force_enable = False
        assert not other.force_enable
    finally:
        other.close()
        status.close()


def test_ring_rejects_bad_shapes():
    with pytest.raises(ValueError):
        Ring.create(["a", "a"], 8)
    with pytest.raises(ValueError):
        Ring.create(["a"], 1)


def _event_writer(name, count):
    events = EventRing.attach(name)
    for i in range(count):
        events.put(("n", i, "x" * (i % 50)))
        if i % 97 == 0:
            time.sleep(0.001)
    events.put(("big", "y" * 10_000))
    events.close()


def test_event_ring_delivers_in_order_and_counts_what_a_slow_reader_lost():
    events = EventRing.create(slots=16, slot_size=256)
    try:
        proc = mp.get_context("spawn").Process(target=_event_writer, args=(events.name, 3000))
        proc.start()
        got = []
        while True:
            event = events.get()
            if event is None:
                if not proc.is_alive() and events.get() is None:
                    break
                continue
            got.append(event)
        proc.join(10)
        ours = [e for e in got if isinstance(e, tuple) and e[0] == "n"]
        numbers = [e[1] for e in ours]
        assert numbers == sorted(numbers) and len(set(numbers)) == len(numbers)
        assert all(e == ("n", e[1], "x" * (e[1] % 50)) for e in ours)
        assert len(numbers) + events.lost == 3000
        assert isinstance(got[-1], Notice) and got[-1].level == "warning" and "too large" in got[-1].text
    finally:
        events.close()
