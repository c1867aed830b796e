"""The emulator over a real pty, driven by a minimal host: handshake, PING/PONG, START and streaming,
ARM and the ramp, the watchdog's bound (10 tries), corrupt and lost frames counted, SIGTERM removes the link,
bad options."""

import os
import signal
import subprocess
import sys
import time

import pytest

from studyapp.device import messages
from tests.device.emulator_process import ROOT, Host, start_emulator, stop_emulator

RATE = 5000
LATE_OK = 250  # samples ahead: 50 ms


@pytest.fixture(scope="module")
def emulator(tmp_path_factory):
    link = tmp_path_factory.mktemp("emu") / "device"
    core = os.environ.get("STUDYAPP_TEST_CORE", "auto")
    proc = start_emulator(link, "--gesture", "hold", "--core", core)
    host = Host(link)
    yield link, proc, host
    host.close()
    stats = stop_emulator(proc)
    assert not os.path.lexists(link)
    assert stats["samples"] > 0
    assert stats["core"] == ("c" if core == "auto" else core)  # this machine builds the C core: its bytes are tested


def handshake(host):
    host.send(messages.Hello())
    return host.wait(messages.Info)


def test_handshake_and_ping(emulator):
    _, _, host = emulator
    info = handshake(host)
    assert (info.protocol_version, info.rate_hz, info.impulsive_n, info.sustained_n) == (1, RATE, 200.0, 60.0)
    assert info.channels == messages.SI_CHANNELS and info.name == "studyapp emulator"
    pongs = []
    for nonce in range(5):
        t = time.perf_counter()
        host.send(messages.Ping(nonce))
        pongs.append(host.wait(messages.Pong, where=lambda m, n=nonce: m.nonce == n))
        assert time.perf_counter() - t < 1.0
    samples = [p.sample for p in pongs]
    assert samples == sorted(samples) and samples[-1] > samples[0]  # the device's clock runs


def stream(host, latency, n, force=0.0, start=True, packet=1):
    """Answer ``n`` sensor samples, each SENSORS frame with one FORCE(first + latency, ...); the last answered."""
    if start:
        host.send(messages.Start(packet, latency))
        host.wait(messages.State, where=lambda m: m.streaming)
    last = None
    answered = 0
    while answered < n:
        for m in host.poll(0.05):
            if isinstance(m, messages.Sensors):
                host.send(messages.Force(m.sample + latency, (force,) * len(m.values)))
                last = m.sample + len(m.values) - 1
                answered += len(m.values)
    return last


def test_streaming_counts_samples(emulator):
    _, _, host = emulator
    handshake(host)
    host.send(messages.Start(1, 5))
    host.wait(messages.State, where=lambda m: m.streaming)
    frames = []
    while len(frames) < 200:
        frames += [m for m in host.poll(0.05) if isinstance(m, messages.Sensors)]
    samples = [f.sample for f in frames]
    assert samples == list(range(samples[0], samples[0] + len(samples)))  # one per sample, none skipped
    assert all(len(f.values) == 1 and not f.flags & messages.FLAG_ARMED for f in frames)
    x = [f.values[0][0] for f in frames]
    assert all(abs(v) < 0.011 for v in x)
    host.send(messages.Stop())
    host.wait(messages.State, where=lambda m: not m.streaming)


@pytest.mark.parametrize("latency", [5, 25])
def test_arm_ramp_and_watchdog_bound(emulator, latency):
    """Ten tries: stream armed (packets of 5 samples) with forces 5 ms ahead for 0.1 s, then stop answering.
    The device's FAULT WATCHDOG says where the force reached 0 (sample) and where the last feeding host frame
    arrived (detail): that span is at most latency + 2 ms in the device's time, whenever the host stopped (on
    a loaded machine the host may fall behind before its stop, which is a stop too). The wall time from the
    host's last write to reading the FAULT is reported for the tries that reached the stop."""
    _, _, host = emulator
    handshake(host)
    bounds, walls = [], []
    for _ in range(10):
        host.send(messages.Start(5, latency), messages.Arm(10))
        host.wait(messages.State, where=lambda m: m.armed)
        stream(host, latency, 500, force=1.0, start=False)
        t_stop = time.perf_counter()
        early = any(isinstance(m, messages.Fault) and m.code == messages.WATCHDOG for m in host.inbox)
        fault = host.wait(messages.Fault, where=lambda m: m.code == messages.WATCHDOG)
        if not early:
            walls.append(time.perf_counter() - t_stop)
        bounds.append((fault.sample - fault.detail) / RATE)
        host.send(messages.Stop())
        host.wait(messages.State, where=lambda m: not m.streaming and not m.armed)
        host.clear()
    limit = latency / RATE + 0.002
    wall = f"{min(walls) * 1e3:.2f}..{max(walls) * 1e3:.2f} ms" if walls else "-"
    print(f"watchdog over 10 tries, latency {latency / RATE * 1e3:g} ms: last host frame -> force 0 in the device's time "
          f"{min(bounds) * 1e3:.2f}..{max(bounds) * 1e3:.2f} ms (bound {limit * 1e3:.1f} ms); host's last write "
          f"-> FAULT read {wall} ({len(walls)} tries reached the stop)")
    assert max(bounds) <= limit


def test_ramp_and_armed_flags(emulator):
    _, _, host = emulator
    handshake(host)
    host.send(messages.Start(5, LATE_OK), messages.Arm(4))  # 4 ms: 20 samples of ramp
    host.wait(messages.State, where=lambda m: m.armed)
    # the frames read with the State (a loaded machine reads many at once) are the ramp's first: poll gives them
    flags = []
    while len(flags) < 40:
        for m in host.poll(0.05):
            if isinstance(m, messages.Sensors):
                host.send(messages.Force(m.sample + LATE_OK, (0.5,) * len(m.values)))
                flags.append(m.flags)
    assert all(f & messages.FLAG_ARMED and not f & messages.FLAG_FAULT for f in flags)
    ramping = [bool(f & messages.FLAG_RAMPING) for f in flags]
    assert ramping[0] and not ramping[-1] and ramping == sorted(ramping, reverse=True)
    host.send(messages.Disarm(messages.EMERGENCY_STOP), messages.Stop())
    host.wait(messages.State, where=lambda m: not m.armed and not m.streaming)


def test_no_force_before_arm(emulator):
    """Hold gesture: a +-40 N square wave (250 Hz) commanded while disarmed leaves the accelerometer at its
    noise; armed, it shakes the handle (a = F / m). The host answers 50 ms ahead, so that a loaded machine's
    tails do not starve the watchdog."""
    _, _, host = emulator
    handshake(host)

    def accel_rms(n, amplitude):
        acc = []
        while len(acc) < n:
            for m in host.poll(0.05):
                if isinstance(m, messages.Sensors):
                    k = m.sample + LATE_OK
                    host.send(messages.Force(k, tuple(amplitude if ((k + i) // 10) % 2 else -amplitude
                                                      for i in range(len(m.values)))))
                    acc += [r[1] for r in m.values]
        tail = acc[n // 2:]
        mean = sum(tail) / len(tail)
        return (sum((v - mean) ** 2 for v in tail) / len(tail)) ** 0.5

    host.send(messages.Start(5, LATE_OK))
    host.wait(messages.State, where=lambda m: m.streaming)
    rest = accel_rms(200, 0.0)
    disarmed = accel_rms(200, 40.0)
    host.send(messages.Arm(0))
    host.wait(messages.State, where=lambda m: m.armed)
    armed = accel_rms(400, 40.0)
    host.send(messages.Disarm(0), messages.Stop())
    host.wait(messages.State, where=lambda m: not m.streaming)
    print(f"acceleration rms: at rest {rest:.3g}, 40 N disarmed {disarmed:.3g}, armed {armed:.3g} m/s^2")
    assert disarmed < 2.0 * rest + 1.0
    assert armed > 20.0 * disarmed


def test_state_counts_late_frames(emulator):
    _, _, host = emulator
    handshake(host)
    host.send(messages.Start(1, 5))
    m = host.wait(messages.Sensors)
    host.send(messages.Force(m.sample, (1.0, 1.0)))  # both passed by the time they arrive
    host.send(messages.Stop())
    state = host.wait(messages.State, where=lambda s: not s.streaming)
    assert state.late >= 2


def test_corrupt_and_lost_frames_are_counted(tmp_path):
    link = tmp_path / "dev"
    proc = start_emulator(link, "--gesture", "hold", "--corrupt", "0.3", "--loss", "0.1", "--seed", "3")
    host = Host(link)
    try:
        for nonce in range(200):
            host.send(messages.Ping(nonce))
            host.poll(0.002)
        time.sleep(0.2)
        host.poll(0.1)
    finally:
        host.close()
        stats = stop_emulator(proc)
    flipped, lost = stats["link_flipped_in"], stats["link_lost_in"]
    assert flipped > 10 and lost > 5 and stats["link_flipped_out"] > 10
    # a flipped frame is corrupt; a flipped delimiter merges two frames into one corrupt run, a flip to 0x00
    # splits one into two
    assert 0.5 * flipped <= stats["corrupt"] <= 2 * flipped
    assert stats["lost"] >= lost  # seq gaps: the lost frames and the corrupt ones
    assert host.receiver.corrupt > 0 and host.receiver.lost > 0
    print(f"200 PINGs, --corrupt 0.3 --loss 0.1: to the device {flipped} flipped, {lost} lost -> corrupt "
          f"{stats['corrupt']}, seq gaps {stats['lost']}; to the host {stats['link_flipped_out']} flipped -> "
          f"corrupt {host.receiver.corrupt}, gaps {host.receiver.lost}")


def test_sigterm_and_sigint_remove_the_link(tmp_path):
    for sig in (signal.SIGTERM, signal.SIGINT):
        link = tmp_path / f"dev{int(sig)}"
        proc = start_emulator(link, "--core", "python")
        assert os.path.islink(link) and os.readlink(link).startswith("/dev/pts/")
        stop_emulator(proc, sig)
        assert proc.returncode == 0
        assert not os.path.lexists(link)


def run_cli(*args):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "studyapp", "device-emulator", *args], capture_output=True,
                          text=True, env=env, cwd=ROOT, timeout=120)


@pytest.mark.parametrize("args, word", [
    (["--rate", "0"], "--rate"), (["--rate", "5000.5"], "--rate"), (["--gesture", "bow"], "--gesture"),
    (["--loss", "1.5"], "--loss"), (["--corrupt", "-0.1"], "--corrupt"), (["--format", "i8"], "--format"),
    (["--latency", "-1"], "--latency"), (["--lockstep", "--loss", "0.1"], "--lockstep"),
    (["--disconnect-after", "0"], "--disconnect-after"), (["--core", "fpga"], "--core"),
    (["--watchdog-ms", "0"], "--watchdog-ms"),
    (["--loop", "fpga"], "--loop"), (["--loop", "device", "--core", "python"], "--core python"),
    (["--loop", "device", "--keepalive-ms", "0"], "--keepalive-ms"),
    (["--loop", "device", "--keepalive-ms", "65536"], "--keepalive-ms"),
    (["--keepalive-ms", "200"], "--keepalive-ms"), (["--loop", "device", "--watchdog-ms", "5"], "--watchdog-ms"),
])
def test_bad_options_one_line_exit_2(tmp_path, args, word):
    link = tmp_path / "dev"
    r = run_cli("--link", str(link), *args)
    assert r.returncode == 2 and r.stdout == ""
    assert len(r.stderr.strip().splitlines()) == 1 and word in r.stderr
    assert not os.path.lexists(link)


def test_refuses_to_replace_a_path(tmp_path):
    taken = tmp_path / "file"
    taken.write_text("participant data")
    r = run_cli("--link", str(taken))
    assert r.returncode == 2 and "exists" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert taken.read_text() == "participant data"
    r = run_cli("--link", str(tmp_path / "missing" / "dev"))
    assert r.returncode == 2 and "does not exist" in r.stderr


def test_replaces_its_own_stale_link(tmp_path):
    link = tmp_path / "dev"
    os.symlink("/dev/pts/999999", link)
    proc = start_emulator(link, "--core", "python")
    assert os.readlink(link) != "/dev/pts/999999"
    stop_emulator(proc)
    assert not os.path.lexists(link)


def test_counts_format_and_disconnect(tmp_path):
    """--format counts: INFO announces i32 channels with their gains and SENSORS carries integers;
    --disconnect-after closes the pty (the host reads end-of-file or EIO), removes the link, exits 0."""
    from studyapp.device.emulator import COUNT_CHANNELS
    link = tmp_path / "dev"
    proc = start_emulator(link, "--format", "counts", "--disconnect-after", "3", "--core", "python")
    host = Host(link)
    try:
        info = handshake(host)
        assert info.channels == COUNT_CHANNELS
        host.send(messages.Start(4, 40))
        frame = host.wait(messages.Sensors)
        assert len(frame.values) == 4 and all(isinstance(v, int) for r in frame.values for v in r)
        assert all(abs(x) <= 0.011 for x, _, _ in frame.si(info.channels))
        proc.wait(timeout=60)
        assert proc.returncode == 0 and not os.path.lexists(link)
        closed = False
        for _ in range(1000):
            try:
                if os.read(host.fd, 1 << 16) == b"":
                    closed = True
                    break
            except BlockingIOError:
                time.sleep(0.01)
            except OSError:
                closed = True
                break
        assert closed
    finally:
        host.close()
        if proc.poll() is None:
            proc.kill()
