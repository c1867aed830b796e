"""firmware/example_isr.c, a lab's firmware for a device loop, built with the system's C compiler from a header
that ``studyapp firmware-params`` writes, speaks protocol version 2 and runs the host's own loop.

The board here is a test's (tests/device/example_board/board.c: sensors and the host's bytes from ctypes); the
host's side is the codec (loop_messages) and, as the reference, the C loop on the host's own arrays
(loop_bank.device_loop, c_loop.CLoop), which tests/device/test_c_loop.py holds equal to the numba loop.
"""

import ctypes
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.device import c_loop, frames, loop_bank, loop_messages as lm, messages as msg
from studyapp.device.loop_image import image_crc
from studyapp.device.streams import Sender
from studyapp.model.control import C_BOWING, C_FORCE_SCALE, C_GAIN, C_PEAK, C_SOURCE
from studyapp.synthetic import stick_slip

ROOT = Path(__file__).resolve().parents[2]
FIRMWARE = ROOT / "firmware"
BOARD = Path(__file__).resolve().parent / "example_board" / "board.c"
RATE = 5000
FLAGS = ["-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-pedantic", "-Werror", "-fPIC", "-shared"]


def build(tmp_path, *options):
    header = tmp_path / "studyapp_params.h"
    assert main(["firmware-params", "--rate", str(RATE), *options, "-o", str(header)]) == 0
    compiler = shutil.which("cc")
    if compiler is None:
        pytest.skip("no C compiler cc (scripts/system-deps.txt: gcc)")
    sources = [FIRMWARE / "example_isr.c", BOARD, *sorted(FIRMWARE.glob("studyapp_*.c"))]
    target = tmp_path / "example.so"
    r = subprocess.run([compiler, *FLAGS, f"-I{FIRMWARE}", f"-I{tmp_path}", "-o", str(target), *map(str, sources),
                        "-lm"], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lib = ctypes.CDLL(str(target))
    lib.test_set_sensors.argtypes = [ctypes.POINTER(ctypes.c_double)]
    lib.test_force.restype = ctypes.c_double
    lib.test_host_write.argtypes = [ctypes.c_char_p, ctypes.c_uint32]
    lib.test_host_read.argtypes = [ctypes.c_char_p, ctypes.c_uint32]
    lib.test_host_read.restype = ctypes.c_uint32
    return lib


class Host:
    def __init__(self, lib):
        self.lib, self.sender, self.reader, self.channels = lib, Sender(), frames.FrameReader(), None

    def send(self, *items):
        data = b"".join(self.sender.frame(m) for m in items)
        assert self.lib.test_host_write(data, len(data)) == 0

    def read(self):
        buf = ctypes.create_string_buffer(1 << 16)
        got = []
        while (n := self.lib.test_host_read(buf, len(buf))) > 0:
            for payload in self.reader.feed(buf.raw[:n]):
                _, m = lm.parse(payload, self.channels)
                if isinstance(m, msg.Info):
                    self.channels = m.channels
                got.append(m)
        return got


def sample(lib, row):
    lib.test_set_sensors((ctypes.c_double * len(row))(*row))
    lib.studyapp_sample_isr()


@pytest.mark.parametrize("source", ["KALLEV", "LEASTSQ", "LVT"])
def test_the_example_firmware_runs_the_hosts_loop_bit_for_bit(tmp_path, source):
    lib = build(tmp_path)
    assert lib.studyapp_init() == 0
    host = Host(lib)
    host.send(msg.Hello(protocol_version=lm.LOOP_VERSION))
    sample(lib, (0.0, 0.0, 0.0))  # the device answers HELLO from its sample interrupt
    (info,) = [m for m in host.read() if isinstance(m, msg.Info)]
    loop = loop_bank.device_loop(RATE, accelerometer=True)
    section = lm.loop_info(info)
    # the header is the host's own loop: the image the host checks, the estimators in the host's order
    assert section.loop == lm.DEVICE_LOOP and section.image == image_crc(RATE, loop.control.arrays)
    assert section.kinds == tuple(int(k) for k in loop.bank.kinds)

    names = loop_bank.estimator_names(True)
    index = lm.SOURCE_VELOCITY_SENSOR if source == "LVT" else names.index(source)
    fmax = 3.0
    ctl = loop.control.arrays[0]
    gain = fmax / ctl[C_PEAK]
    signal = stick_slip(RATE, 0.4, seed=3)
    rows = np.column_stack([signal["position"], signal["acceleration"], signal["velocity_lvt"]])
    host.send(msg.Arm(ramp_ms=10), msg.Start(packet=10, latency=10),
              lm.Control(id=1, sample=1, source=index, bowing=1, reset=1, gain=gain, force_scale=1.0))
    telemetry = []
    for k, row in enumerate(rows):
        sample(lib, row)
        if k % 50 == 0:
            host.send(lm.Alive(seen=k))
        telemetry += [m for m in host.read() if isinstance(m, lm.Telemetry)]
    got = {m.sample + i: r for m in telemetry for i, r in enumerate(m.rows)}
    assert len(got) >= len(rows) - 10

    reference = c_loop.CLoop(loop.control.arrays)
    first = min(got)
    # before the first CONTROL since START: the bow lifted, gain 0, force scale 1, the velocity sensor
    ctl[C_SOURCE], ctl[C_BOWING], ctl[C_GAIN], ctl[C_FORCE_SCALE] = lm.SOURCE_VELOCITY_SENSOR, 0.0, 0.0, 1.0
    forces, bridges, applied_at = [], [], None
    for k in range(first, first + len(got)):
        if got[k][-1] == 1 and applied_at is None:  # CONTROL 1 takes effect at this row: so does the reference
            ctl[C_SOURCE], ctl[C_BOWING], ctl[C_GAIN], ctl[C_FORCE_SCALE] = index, 1.0, gain, 1.0
            reference.reset_string()
            applied_at = k
        forces.append(reference.sample(k, *rows[k - first]))
        bridges.append(reference.out.bridge_velocity)
    assert applied_at == 1  # at its tag
    sent = np.array([got[k][3] for k in sorted(got)])
    assert np.abs(sent).max() > 0.1 * fmax  # the string was bowed and pulled
    np.testing.assert_array_equal(sent.view(np.int64), np.array(forces).view(np.int64))
    np.testing.assert_array_equal(np.array([got[k][5] for k in sorted(got)]).view(np.int64),
                                  np.array(bridges).view(np.int64))
    applied = np.array([got[k][4] for k in sorted(got)])
    assert np.all(np.abs(applied) <= np.abs(sent) + 1e-12)  # the safety core only ever lowers the force


def test_the_header_is_refused_over_an_existing_file_and_for_a_bad_rate(tmp_path, capsys):
    header = tmp_path / "studyapp_params.h"
    header.write_text("/* the lab's own */\n")
    assert main(["firmware-params", "--rate", "5000", "-o", str(header)]) == 2
    assert header.read_text() == "/* the lab's own */\n"
    assert main(["firmware-params", "--rate", "5000.5", "-o", str(tmp_path / "x.h")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "exists" in err[0] and "--rate 5000.5" in err[1]
    assert not (tmp_path / "x.h").exists()


def test_without_an_accelerometer_the_header_has_no_acceleration_channel_nor_its_estimators(tmp_path):
    lib = build(tmp_path, "--no-accelerometer", "--format", "counts")
    assert lib.studyapp_init() == 0
    text = (tmp_path / "studyapp_params.h").read_text()
    assert "#define SP_N_CHANNELS 2u" in text and f"#define SP_N_EST {len(loop_bank.STUDY)}u" in text
