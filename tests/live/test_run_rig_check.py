"""``studyapp run --device``: the rig check's line before a session on a link (cli/device_choice.py), and the
option refused headless (the simulated participant runs on the simulated device)."""

import subprocess
import sys
from pathlib import Path

import pytest

from studyapp.cli.device_choice import rig_check_line
from studyapp.experiment.protocol import load_protocol
from studyapp.live import rig_check

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"


def test_run_prints_the_warning_line_on_a_link_and_nothing_on_the_simulated_device(monkeypatch):
    monkeypatch.setattr(rig_check, "predict", lambda req: {"LOWPASS": 2.89, "LEVANT": 2.89, "LVT": 3.09})
    said = []
    protocol = load_protocol(DEMO)
    req, prediction, warning = rig_check_line(protocol, "/tmp/studyapp-device", said.append)
    assert req.rig.latency_ms == 1.0 and prediction["LVT"] == 3.09
    assert warning == said[-1] and warning.startswith("warning: at this rig's link latency of 5 samples (1.00 ms")
    assert "below 1.5x" in said[-2]
    said.clear()
    assert rig_check_line(protocol, None, said.append) is None and said == []


def test_run_says_a_device_loop_is_the_papers_own_loop_and_predicts_nothing(monkeypatch):
    monkeypatch.setattr(rig_check, "predict", lambda req: pytest.fail("a device loop needs no prediction"))
    said = []
    assert rig_check_line(load_protocol(DEMO), "/tmp/studyapp-device", said.append, loop="device") is None
    assert said == ["rig check: the loop runs on the device: the paper's own loop (latency 0); LVT's margin is the "
                    "model's own, nothing to predict"]


def test_device_is_refused_headless(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", str(DEMO), "--participant", "X1",
                           "--simulated-participant", "--headless", "--device", "/tmp/x", "--results",
                           str(tmp_path)], capture_output=True, text=True, timeout=300, cwd=ROOT,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and lines[0].endswith(
        "--device /tmp/x: allowed with --headless is only simulated: a headless session steps the simulated device "
        "as fast as it can, and a device on a link runs on its own clock; run it without --headless (the console)")
    assert not any(tmp_path.iterdir())


def test_run_help_says_why_a_device_is_refused_headless():
    """Issue 41 item 12: ``--help`` did not say that ``--headless --device`` is refused."""
    proc = subprocess.run([sys.executable, "-m", "studyapp", "run", "--help"], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    text = " ".join(proc.stdout.split())
    assert proc.returncode == 0
    assert ("(the console's; not with --headless: a headless session steps the simulated device as fast as it can, "
            "and a device on a link runs on its own clock)") in text


def test_a_device_that_is_no_link_is_one_line_before_anything_starts(tmp_path):
    regular = tmp_path / "not-a-device"
    regular.write_text("")
    proc = subprocess.run([sys.executable, "-m", "studyapp", "run", "--protocol", str(DEMO), "--participant", "X2",
                           "--device", str(regular), "--results", str(tmp_path / "results")],
                          capture_output=True, text=True, timeout=300, cwd=ROOT,
                          env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1 and str(regular) in lines[0] and "regular file" in lines[0]
    assert not (tmp_path / "results").exists()


def test_the_warnings_controls_exist_on_the_console_and_reach_its_engines(monkeypatch):
    # issue 41, item 10: the warning named docs/devices.md; the console had no control for the latency or silence
    import argparse
    import re

    from studyapp.cli import device_choice
    from studyapp.errors import ParameterError

    named = set(re.findall(r"--device-[a-z]+", rig_check.REMEDY))
    assert named == {"--device-latency", "--device-silence"}
    done = subprocess.run([sys.executable, "-m", "studyapp", "gui", "--help"], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)
    assert done.returncode == 0 and all(option in done.stdout for option in named)
    args = argparse.Namespace(device_latency=2, device_silence=0.5)
    assert device_choice.link_options(args, "/tmp/dev") == {"device_latency": 2, "device_silence": 0.5}
    with pytest.raises(ParameterError, match="need --device"):
        device_choice.link_options(args, None)
    with pytest.raises(ParameterError, match="device latency = 0"):
        device_choice.link_options(argparse.Namespace(device_latency=0, device_silence=None), "/tmp/dev")
    said = []
    monkeypatch.setattr(rig_check, "predict", lambda req: {"LOWPASS": 2.89, "LEVANT": 2.89, "LVT": 3.09})
    req, _, warning = rig_check_line(load_protocol(DEMO), "/tmp/studyapp-device", said.append, latency=2)
    assert req.rig.latency_samples == 2 and "(now 2)" in warning
