"""The codec against independent references: CRC-16/CCITT-FALSE's catalogue check value and a bit-by-bit
reference, COBS against the published examples (Cheshire & Baker 1999; Wikipedia's table), round trips
(hypothesis), and corruption: no single-bit flip of a frame is ever applied."""

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studyapp.device import cobs, frames, messages
from studyapp.device.crc import crc16
from studyapp.device.errors import ProtocolError
from studyapp.device.frames import FrameReader


def crc_bitwise(data):
    """CRC-16/CCITT-FALSE one bit at a time, straight from its definition (poly 0x1021, init 0xFFFF)."""
    crc = 0xFFFF
    for byte in data:
        for i in range(7, -1, -1):
            bit = (byte >> i) & 1
            top = (crc >> 15) & 1
            crc = (crc << 1) & 0xFFFF
            if top ^ bit:
                crc ^= 0x1021
    return crc


def test_crc_check_value():
    assert crc16(b"123456789") == 0x29B1
    assert crc_bitwise(b"123456789") == 0x29B1
    assert crc16(b"") == 0xFFFF


@given(st.binary(max_size=300))
def test_crc_equals_bitwise_reference(data):
    assert crc16(data) == crc_bitwise(data)


def _seq(a, b):
    return bytes(range(a, b + 1))


# Wikipedia, "Consistent Overhead Byte Stuffing", encoding examples (the delimiter left out)
COBS_EXAMPLES = [
    (b"\x00", b"\x01\x01"),
    (b"\x00\x00", b"\x01\x01\x01"),
    (b"\x00\x11\x00", b"\x01\x02\x11\x01"),
    (b"\x11\x22\x00\x33", b"\x03\x11\x22\x02\x33"),
    (b"\x11\x22\x33\x44", b"\x05\x11\x22\x33\x44"),
    (b"\x11\x00\x00\x00", b"\x02\x11\x01\x01\x01"),
    (_seq(0x01, 0xFE), b"\xff" + _seq(0x01, 0xFE)),
    (b"\x00" + _seq(0x01, 0xFE), b"\x01\xff" + _seq(0x01, 0xFE)),
    (_seq(0x01, 0xFF), b"\xff" + _seq(0x01, 0xFE) + b"\x02\xff"),
    (_seq(0x02, 0xFF) + b"\x00", b"\xff" + _seq(0x02, 0xFF) + b"\x01\x01"),
    (_seq(0x03, 0xFF) + b"\x00\x01", b"\xfe" + _seq(0x03, 0xFF) + b"\x02\x01"),
    (b"", b"\x01"),
]


@pytest.mark.parametrize("raw, stuffed", COBS_EXAMPLES)
def test_cobs_published_examples(raw, stuffed):
    assert cobs.encode(raw) == stuffed
    assert cobs.decode(stuffed) == raw


@given(st.binary(max_size=1200))
def test_cobs_round_trip_and_overhead(data):
    stuffed = cobs.encode(data)
    assert 0 not in stuffed
    assert len(stuffed) <= len(data) + 1 + len(data) // 254
    assert cobs.decode(stuffed) == data


@pytest.mark.parametrize("bad", [b"\x00", b"\x03\x11", b"\x03\x11\x00", b"\x02\x11\x05"])
def test_cobs_malformed(bad):
    with pytest.raises(ProtocolError, match="COBS"):
        cobs.decode(bad)


payloads = st.binary(min_size=frames.MIN_PAYLOAD, max_size=frames.MAX_PAYLOAD)


@given(st.lists(payloads, max_size=5), st.lists(st.integers(1, 64), max_size=8))
@settings(max_examples=60)
def test_frames_round_trip_any_split(items, cuts):
    wire = b"".join(frames.encode(p) for p in items)
    reader = FrameReader()
    got = []
    at = 0
    for c in cuts + [len(wire)]:
        got += reader.feed(wire[at:at + c])
        at += c
    got += reader.feed(wire[at:])
    assert got == items
    assert reader.corrupt == 0 and reader.frames == len(items)


def test_frame_layout_by_hand():
    payload = bytes((0x87, 0x00, 0x04, 0x03, 0x02, 0x01))
    crc = crc_bitwise(payload)
    assert frames.encode(payload) == cobs.encode(payload + struct.pack("<H", crc)) + b"\x00"


def test_overlong_run_is_dropped_and_reader_resyncs():
    reader = FrameReader()
    good = frames.encode(b"\x87\x01\x00\x00\x00\x00")
    assert reader.feed(b"\x05" * (frames.MAX_ENCODED + 10)) == []
    assert reader.feed(b"\x00" + good) == [b"\x87\x01\x00\x00\x00\x00"]
    assert reader.corrupt == 1


def test_empty_runs_are_not_frames():
    reader = FrameReader()
    assert reader.feed(b"\x00\x00\x00") == []
    assert reader.corrupt == 0
    with pytest.raises(ProtocolError):
        frames.encode(b"\x01")
    with pytest.raises(ProtocolError):
        frames.encode(b"\x01" * (frames.MAX_PAYLOAD + 1))


INFO = messages.Info(1, 0, 1, 5000, 8, "emulator", "EMU-0001", 0.011, 200.0, 60.0, 1.0, 1, 0)
COUNTS = (messages.Channel(messages.POSITION, messages.I32, 1e-8, 0.0),
          messages.Channel(messages.ACCELERATION, messages.I16, 1e-2, 0.5),
          messages.Channel(messages.VELOCITY, messages.I32, 1e-7, 0.0))
SAMPLES = [
    messages.Hello(1), messages.Force(123456, (1.5, -2.25, 0.0)), messages.Arm(250), messages.Disarm(1),
    messages.Start(4, 5), messages.Stop(), messages.Ping(0xDEADBEEF), messages.Keepalive(),
    INFO, messages.Sensors(99, 5, ((0.001, -0.5, 0.02), (0.002, 0.5, -0.02))), messages.Pong(7, 8),
    messages.Fault(messages.WATCHDOG, 1000, 990), messages.State(1, 1, 0, 2, 3, 4),
]


@pytest.mark.parametrize("message", SAMPLES, ids=lambda m: type(m).__name__)
def test_messages_round_trip(message):
    seq, back = messages.parse(message.pack(200), messages.SI_CHANNELS)
    assert (seq, back) == (200, message)


finite = st.floats(allow_nan=False, allow_infinity=False)


@given(st.integers(0, 2**32 - 1), st.lists(finite, min_size=1, max_size=64), st.integers(0, 255))
def test_force_round_trip(sample, forces, seq):
    message = messages.Force(sample, tuple(forces))
    assert messages.parse(frames.decode(frames.encode(message.pack(seq))[:-1])) == (seq, message)


@given(st.integers(0, 2**32 - 1), st.integers(0, 255),
       st.lists(st.tuples(st.integers(-2**31, 2**31 - 1), st.integers(-2**15, 2**15 - 1),
                          st.integers(-2**31, 2**31 - 1)), min_size=1, max_size=20))
def test_sensors_counts_round_trip(sample, flags, rows):
    message = messages.Sensors(sample, flags, tuple(rows))
    assert messages.Sensors.parse(message.pack(0, COUNTS), COUNTS) == message
    si = message.si(COUNTS)
    assert si[0][1] == pytest.approx(1e-2 * rows[0][1] + 0.5)


@given(st.text(max_size=10), st.text(max_size=10), st.integers(1, 255), st.integers(0, 65535))
def test_info_round_trip(name, serial, rate, watchdog):
    if len(name.encode()) > 32 or len(serial.encode()) > 32:
        return
    info = messages.Info(1, 2, 3, rate, 42, name, serial, 0.01, 100.0, 50.0, 0.5, watchdog, 10, COUNTS)
    info = messages.Info(**{**info.__dict__, "max_packet": min(42, messages.max_packet(COUNTS))})
    assert messages.parse(info.pack(9)) == (9, info)


@pytest.mark.parametrize("payload, field", [
    (b"\x82\x00" + struct.pack("<IB", 1, 0), "FORCE.count"),
    (b"\x82\x00" + struct.pack("<IB", 1, 2) + struct.pack("<d", 1.0), "FORCE body length"),
    (b"\x82\x00" + struct.pack("<IBd", 1, 1, float("nan")), r"FORCE.force\[0\]"),
    (b"\x82\x00" + struct.pack("<IBd", 1, 1, float("inf")), r"FORCE.force\[0\]"),
    (b"\x84\x00\x07", "DISARM.reason"),
    (b"\x83\x00\x01", "ARM body"),
    (b"\x85\x00\x00\x01\x00", "START.packet"),
    (b"\x85\x00\x05\x03\x00", "START.latency"),
    (b"\x99\x00", "type 0x99"),
    (b"\x02\x00" + struct.pack("<IBB", 0, 1, 0), "SENSORS body length"),
    (b"\x04\x00" + struct.pack("<BII", 9, 0, 0), "FAULT.code"),
])
def test_bad_bodies_name_the_field(payload, field):
    with pytest.raises(ProtocolError, match=field):
        messages.parse(payload, messages.SI_CHANNELS)


def test_info_refuses_bad_text_and_limits():
    good = INFO.pack(0)
    bad_name = bytearray(good)
    name_at = 2 + 9  # header, protocol_version..max_packet
    bad_name[name_at + 1] = 0xFF
    with pytest.raises(ProtocolError, match="INFO.name: not valid UTF-8"):
        messages.parse(bytes(bad_name))
    with pytest.raises(ProtocolError, match="INFO.impulsive_n"):
        messages.Info(**{**INFO.__dict__, "impulsive_n": float("nan")}).pack()
    with pytest.raises(ProtocolError, match="INFO.name"):
        messages.Info(**{**INFO.__dict__, "name": "x" * 33}).pack()
    with pytest.raises(ProtocolError, match="INFO.max_packet"):
        messages.Info(**{**INFO.__dict__, "max_packet": 43}).pack()
    with pytest.raises(ProtocolError, match="SENSORS before INFO"):
        messages.parse(messages.Sensors(0, 0, ((0.0, 0.0, 0.0),)).pack())


@pytest.mark.parametrize("message", SAMPLES, ids=lambda m: type(m).__name__)
def test_every_single_bit_flip_is_never_applied(message):
    """Each bit of the frame flipped in turn, a good frame after it: only the good frame may come out."""
    wire = frames.encode(message.pack(17))
    after = messages.Ping(42).pack(18)
    follow = frames.encode(after)
    for i in range(len(wire) * 8):
        bad = bytearray(wire)
        bad[i // 8] ^= 1 << (i % 8)
        reader = FrameReader()
        got = reader.feed(bytes(bad) + follow)
        assert all(p == after for p in got), (i, got)
        assert reader.corrupt >= 1


def test_streams_count_lost_and_corrupt():
    from studyapp.device.streams import Sender, device_receiver
    sender = Sender()
    wires = [sender.frame(messages.Ping(i)) for i in range(6)]
    receiver = device_receiver()
    bad = bytearray(wires[2])
    bad[3] ^= 0x10
    got = receiver.feed(wires[0] + wires[1] + bytes(bad) + wires[4] + wires[5]
                        + frames.encode(messages.Pong(1, 2).pack(6)))
    assert [m.nonce for m in got] == [0, 1, 4, 5]
    assert receiver.lost == 2  # seq 2 (corrupt) and 3 (dropped)
    assert receiver.corrupt == 2  # the flipped frame and a device type at the device


def test_host_receiver_takes_the_channels_from_info():
    from studyapp.device.emulator import COUNT_CHANNELS
    from studyapp.device.streams import Sender, host_receiver
    info = messages.Info(**{**INFO.__dict__, "channels": COUNT_CHANNELS})
    sender = Sender(COUNT_CHANNELS)
    receiver = host_receiver()
    sensors = messages.Sensors(5, 0, ((1, 2, 3),))
    got = receiver.feed(sender.frame(info) + sender.frame(sensors))
    assert got == [info, sensors] and receiver.corrupt == 0
