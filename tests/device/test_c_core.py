"""The C core (firmware/studyapp_device.c) against the Python core (firmware.py, device_side.py): the same
bytes in and the same samples give the same bytes out, the same forces (bit for bit) and the same counters,
over random programs of valid, malformed and corrupted host frames (hypothesis)."""

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studyapp.device import emulator, frames, messages
from studyapp.device.firmware import Firmware

c_core = pytest.importorskip("studyapp.device.c_core")

forces = st.floats(-500.0, 500.0, allow_nan=False) | st.sampled_from([0.0, -0.0, 1e300, -1e300, 5e-324])
starts = st.integers(1, 8).flatmap(lambda p: st.builds(messages.Start, st.just(p), st.integers(p - 1, 60)))
host_messages = st.one_of(
    st.builds(messages.Hello, st.integers(0, 3)),
    st.builds(messages.Ping, st.integers(0, 2**32 - 1)),
    st.just(messages.Keepalive()), st.just(messages.Stop()),
    st.builds(messages.Arm, st.integers(0, 30)),
    st.builds(messages.Disarm, st.integers(0, 2)),
    starts,
    st.builds(messages.Force, st.integers(0, 400), st.lists(forces, min_size=1, max_size=12).map(tuple)),
)


@st.composite
def wire(draw):
    """One frame: a message, a payload that breaks a rule (a CRC that checks), or a damaged frame."""
    kind = draw(st.sampled_from(["message"] * 4 + ["force"] * 4 + ["payload", "flip", "garbage"]))
    seq = draw(st.integers(0, 255))
    if kind == "force":  # tagged from the device's sample counter when it is sent: mostly ahead, some late
        offset = draw(st.integers(-3, 30))
        values = tuple(draw(st.lists(forces, min_size=1, max_size=12)))
        return lambda now: frames.encode(messages.Force(_tag(now, offset), values).pack(seq))
    if kind == "payload":
        body = draw(st.binary(max_size=24))
        return frames.encode(bytes((draw(st.integers(0x80, 0x8A)), seq)) + body)
    if kind == "garbage":
        return draw(st.binary(min_size=1, max_size=30))
    data = bytearray(frames.encode(draw(host_messages).pack(seq)))
    if kind == "flip":
        bit = draw(st.integers(0, len(data) * 8 - 1))
        data[bit // 8] ^= 1 << (bit % 8)
    return bytes(data)


def _tag(now, offset):
    """``offset`` samples from the device's ``now``: mod 2^32 near the wrap (issue 41), else at least 0."""
    return (now + offset) & 0xFFFFFFFF if now >= 2**31 else max(0, now + offset)


session = st.just([lambda now: frames.encode(messages.Start(2, 4).pack(0)),
                   lambda now: frames.encode(messages.Arm(3).pack(1))])
steps = st.lists(st.tuples(st.lists(wire(), max_size=4), st.integers(0, 3), st.integers(0, 25)),
                 min_size=1, max_size=40).flatmap(
    lambda program: st.one_of(st.just(program), session.map(lambda s: [(s, 0, 1)] + program)))


def bits(f):
    return struct.pack("<d", f)


def run_both(info, program, counts, first=0):
    py, c = Firmware(info), c_core.CCore(info)
    py.set_counter(first)
    c.set_counter(first)
    k = 0
    for frames_in, cut, n in program:
        data = b"".join(f(py.now) if callable(f) else f for f in frames_in)
        for part in (data[:cut], data[cut:]):
            py.rx(part)
            c.rx(part)
        assert py.tx() == c.tx()
        for _ in range(n):
            raw = (k * 7 % 1000, -k * 3 % 777, k % 91 - 45) if counts else (k * 1e-6, -0.5 * k, 0.01 * (k % 13))
            k += 1
            py.sample(raw)
            c.sample(raw)
            assert py.needs_force() == c.needs_force()
            assert bits(py.actuate()) == bits(c.actuate())
            assert py.tx() == c.tx()
        assert py.counters() == c.counters()


@given(steps)
@settings(max_examples=150, deadline=None)
def test_c_core_equals_python_core(program):
    run_both(emulator.device_info(emulator.EmulatorConfig(link="-")), program, counts=False)


@given(steps)
@settings(max_examples=40, deadline=None)
def test_c_core_equals_python_core_counts(program):
    run_both(emulator.device_info(emulator.EmulatorConfig(link="-", format="counts", rate=1000)), program, counts=True)


@given(steps)
@settings(max_examples=60, deadline=None)
def test_c_core_equals_python_core_across_the_counter_wrap(program):
    """From 40 samples before 2^32 (sd_set_counter, the emulator's --first-sample): the programs cross the wrap."""
    run_both(emulator.device_info(emulator.EmulatorConfig(link="-")), program, counts=False, first=2**32 - 40)


def test_the_cores_stream_and_answer_forces_across_the_wrap():
    """Armed streaming over the wrap: forces tagged mod 2^32 act on both sides of it, the watchdog stays fed."""
    info = emulator.device_info(emulator.EmulatorConfig(link="-"))
    first = 2**32 - 100
    program = [([frames.encode(messages.Start(4, 8).pack(0)), frames.encode(messages.Arm(0).pack(1))], 0, 0)]
    for block in range(60):
        tag = (first + block * 4 + 8) & 0xFFFFFFFF
        program.append(([frames.encode(messages.Force(tag, (1.0, 2.0, 3.0, 4.0)).pack((block + 2) & 255))], 0, 4))
    run_both(info, program, counts=False, first=first)
    py = Firmware(info)
    py.set_counter(first)
    for frames_in, _, n in program:
        py.rx(b"".join(frames_in))
        for _ in range(n):
            py.sample((0.0, 0.0, 0.0))
            py.actuate()
    counters = py.counters()
    assert counters["now"] == (first + 240) & 0xFFFFFFFF and counters["fault"] == 0 and counters["armed"] == 1
    assert counters["late"] == 0 and counters["missing"] == 0


def test_long_streaming_run_with_clamps_and_watchdog():
    """Armed streaming with large forces (the clamps and the RMS limit engage), then the host stops."""
    info = emulator.device_info(emulator.EmulatorConfig(link="-"))
    program = [([frames.encode(messages.Start(4, 8).pack(0)), frames.encode(messages.Arm(2).pack(1))], 0, 0)]
    seq = 2
    for block in range(400):
        program.append(([frames.encode(messages.Force(block * 4 + 8, (150.0, -250.0, 90.0, 40.0)).pack(seq & 255))],
                        3, 4))
        seq += 1
    program.append(([], 0, 60))
    run_both(info, program, counts=False)


def test_crc_matches():
    lib = c_core.library()
    assert lib.sd_crc16(b"123456789", 9, 0xFFFF) == 0x29B1


def test_build_library_compiles_every_c_file_once_into_a_cache_keyed_by_the_sources(tmp_path, monkeypatch):
    import ctypes

    src = tmp_path / "src"
    src.mkdir()
    (src / "two.h").write_text("int two(void);\n")
    (src / "one.c").write_text('#include "two.h"\nint one(void) { return two() - 1; }\n')
    (src / "two.c").write_text('#include "two.h"\nint two(void) { return 2; }\n')
    monkeypatch.setattr(c_core, "SOURCE_DIR", src)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    sources = ("one.c", "two.c", "two.h")
    path = c_core.build_library("pair", sources)
    assert path.name == "pair.so" and path.parent.parent == tmp_path / "cache" / "studyapp" / "device"
    assert ctypes.CDLL(str(path)).one() == 1  # both units linked into the one library
    built = path.stat().st_mtime_ns
    assert c_core.build_library("pair", sources) == path and path.stat().st_mtime_ns == built  # found, not rebuilt
    (src / "two.h").write_text("int two(void); /* a header's change is a new version */\n")
    assert c_core.build_library("pair", sources).parent != path.parent


def test_build_library_refuses_a_missing_source_and_a_compile_error_in_one_line(tmp_path, monkeypatch):
    monkeypatch.setattr(c_core, "SOURCE_DIR", tmp_path)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    with pytest.raises(c_core.BuildError, match=r"absent\.c not found"):
        c_core.build_library("x", ("absent.c",))
    (tmp_path / "bad.c").write_text("int f(void) { return }\n")
    with pytest.raises(c_core.BuildError, match=r"failed on bad\.c: ") as error:
        c_core.build_library("x", ("bad.c",))
    assert "\n" not in str(error.value)
    assert not list((tmp_path / "cache").rglob("*.so"))  # no half-built library left in the cache


def test_the_device_core_is_the_library_of_its_sources():
    assert c_core.build() == c_core.build_library("studyapp_device", c_core.SOURCES)
