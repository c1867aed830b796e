"""Protocol version 2's messages (loop_messages.py) against the byte layouts of docs/device-protocol.md,
"Version 2": round trips of CONTROL, ALIVE, TELEMETRY and INFO's loop section (struct-packed by hand, not by
the codec), and every bad field a ProtocolError that names it."""

import struct
import zlib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from studyapp.device import frames, loop_messages as lm, messages as msg
from studyapp.device.errors import ProtocolError

COUNTS = (msg.Channel(msg.POSITION, msg.I32, 1e-9, 0.0), msg.Channel(msg.VELOCITY, msg.I16, 1e-6, 0.0))
finite = st.floats(allow_nan=False, allow_infinity=False)


@given(st.integers(1, 65535), st.integers(0, 2**32 - 1), st.one_of(st.integers(0, 31), st.just(-2)),
       st.integers(0, 1), st.integers(0, 1), st.floats(0.0, 1e6), st.floats(0.0, 1.0), st.integers(0, 255))
def test_control_round_trip_and_layout(cid, sample, source, bowing, reset, gain, scale, seq):
    c = lm.Control(cid, sample, source, bowing, reset, gain, scale)
    payload = c.pack(seq)
    assert payload == bytes((0x89, seq)) + struct.pack("<HIbBBdd", cid, sample, source, bowing, reset, gain, scale)
    assert len(payload) == 27
    assert lm.parse(frames.decode(frames.encode(payload)[:-1])) == (seq, c)


@given(st.integers(0, 2**32 - 1), st.integers(0, 255))
def test_alive_round_trip_and_layout(seen, seq):
    payload = lm.Alive(seen).pack(seq)
    assert payload == bytes((0x8A, seq)) + struct.pack("<I", seen) and len(payload) == 6
    assert lm.parse(payload) == (seq, lm.Alive(seen))


@given(st.integers(0, 2**32 - 1), st.integers(0, 255),
       st.lists(st.tuples(st.integers(-2**31, 2**31 - 1), st.integers(-2**15, 2**15 - 1), finite, finite, finite,
                          st.integers(0, 65535)), min_size=1, max_size=lm.max_telemetry_packet(COUNTS)))
def test_telemetry_round_trip_and_layout(sample, flags, rows):
    t = lm.Telemetry(sample, flags, tuple(rows))
    payload = t.pack(3, COUNTS)
    body = struct.pack("<IBB", sample, len(rows), flags) + b"".join(struct.pack("<ihdddH", *r) for r in rows)
    assert payload == b"\x06\x03" + body
    assert lm.parse(payload, COUNTS) == (3, t)


def test_telemetry_packet_fits_the_payload():
    row = 3 * 8 + 26
    assert lm.max_telemetry_packet(msg.SI_CHANNELS) == (1024 - 8) // row == 20
    with pytest.raises(ProtocolError, match="TELEMETRY.count"):
        lm.Telemetry(0, 0, ((0.0,) * 6 + (0,),) * 21).pack(0)


def test_loop_info_round_trip_in_info():
    loop = lm.LoopInfo(lm.DEVICE_LOOP, 200, zlib.crc32(b"image"), (1, 2, 3, 4, 5, 6, 8, 10))
    info = msg.Info(2, 1, 0, 5000, 20, "dev", "S-1", 0.011, 200.0, 60.0, 1.0, 1, 0, msg.SI_CHANNELS, loop.pack())
    payload = info.pack(0)
    assert payload.endswith(struct.pack("<BHIB", 1, 200, zlib.crc32(b"image"), 8) + bytes(loop.kinds))
    back = lm.parse(payload)[1]
    assert back == info and lm.loop_info(back) == loop
    v1 = msg.Info(1, 1, 0, 5000, 20, "dev", "S-1", 0.011, 200.0, 60.0, 1.0, 1, 0)
    assert lm.loop_info(v1) == lm.LoopInfo()


def control_payload(**fields):
    values = {"id": 1, "sample": 0, "source": 0, "bowing": 1, "reset": 0, "gain": 1.0, "force_scale": 1.0, **fields}
    return b"\x89\x00" + struct.pack("<HIbBBdd", *values.values())


@pytest.mark.parametrize("payload, field", [
    (control_payload(id=0), "CONTROL.id"),
    (control_payload(source=-1), "CONTROL.source"),
    (control_payload(source=32), "CONTROL.source"),
    (control_payload(bowing=2), "CONTROL.bowing"),
    (control_payload(reset=7), "CONTROL.reset"),
    (control_payload(gain=float("nan")), "CONTROL.gain"),
    (control_payload(gain=float("inf")), "CONTROL.gain"),
    (control_payload(gain=-1.0), "CONTROL.gain"),
    (control_payload(force_scale=1.5), "CONTROL.force_scale"),
    (control_payload(force_scale=float("nan")), "CONTROL.force_scale"),
    (control_payload()[:-1], "CONTROL body of 24 bytes"),
    (b"\x8a\x00\x01\x02", "ALIVE body of 2 bytes"),
    (b"\x06\x00" + struct.pack("<IBB", 0, 0, 0), "TELEMETRY.count"),
    (b"\x06\x00" + struct.pack("<IBB", 0, 1, 0) + bytes(49), "TELEMETRY body length"),
    (b"\x06\x00\x00", "TELEMETRY ends inside flags"),
])
def test_bad_fields_name_the_field(payload, field):
    with pytest.raises(ProtocolError, match=field):
        lm.parse(payload, msg.SI_CHANNELS)


@pytest.mark.parametrize("loop, field", [
    (lm.LoopInfo(2, 200, 0, ()), "INFO.loop"),
    (lm.LoopInfo(lm.DEVICE_LOOP, 0, 0, ()), "INFO.keepalive_ms"),
    (lm.LoopInfo(lm.DEVICE_LOOP, 65536, 0, ()), "INFO.keepalive_ms"),
    (lm.LoopInfo(lm.DEVICE_LOOP, 200, 1 << 32, ()), "INFO.image"),
    (lm.LoopInfo(lm.DEVICE_LOOP, 200, 0, (1,) * 33), "INFO.estimator_count"),
    (lm.LoopInfo(lm.DEVICE_LOOP, 200, 0, (1, 256)), r"INFO.estimator\[1\]"),
])
def test_bad_loop_info_names_the_field(loop, field):
    with pytest.raises(ProtocolError, match=field):
        loop.pack()


def test_loop_section_length_and_telemetry_before_info():
    with pytest.raises(ProtocolError, match="INFO loop section length"):
        lm.LoopInfo.parse(struct.pack("<BHIB", 1, 200, 0, 3) + b"\x01")
    with pytest.raises(ProtocolError, match="INFO loop section of 3 bytes"):
        lm.LoopInfo.parse(b"\x01\x00\x00")
    with pytest.raises(ProtocolError, match="TELEMETRY before INFO"):
        lm.parse(lm.Telemetry(0, 0, ((0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0),)).pack(0))
