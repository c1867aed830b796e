"""``EngineLoop``: the runner's loop played by the engine (no Qt, no worker: the engine is a recording fake)."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.gui.engine_loop import EngineLoop
from studyapp.model import ClosedLoop, LoopConfig
from studyapp.model.stability import StabilityMonitor

RATE = 5000.0


class RecordingEngine:
    """The parts of ``Engine`` that EngineLoop uses; commands are recorded, status is settable."""

    def __init__(self, names):
        self.names = list(names)
        self.config = type("Config", (), {"rate": RATE})()
        self.sent = []
        self.fault = ""
        self.latched = False

    def __getattr__(self, name):
        if name.startswith("set_") or name == "reset_string":
            return lambda *value: self.sent.append((name, *value))
        raise AttributeError(name)

    def status(self):
        return {"fault": self.fault, "fault_latched": self.latched}


def telemetry_like(out, fmax, scale=1.0):
    n = len(out["force"])
    return {"force": out["force"], "fmax": np.full(n, fmax), "force_scale": np.full(n, scale),
            "source_velocity": out["source_velocity"], "velocity_true": out["velocity_true"],
            "velocity_lvt": out["velocity_lvt"]}


@pytest.fixture(scope="module")
def bowed():
    fmax = 3.0
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=fmax, audio=False))
    return fmax, loop.run(int(0.6 * RATE))


def test_friction_from_the_force_equals_the_loops_own(bowed):
    fmax, out = bowed
    assert np.max(np.abs(out["force"])) > 0.5 * fmax  # really bowing
    np.testing.assert_allclose(-out["force"] / fmax, out["friction"], rtol=1e-12, atol=1e-12)


def test_monitor_verdict_matches_the_loops_monitor(bowed):
    fmax, out = bowed
    engine = RecordingEngine(["LOWPASS"])
    loop = EngineLoop(engine, {"LOWPASS": {}}, "LOWPASS", "strokes")
    reference = StabilityMonitor(RATE)
    half = len(out["force"]) // 2
    for part in (slice(0, half), slice(half, None)):
        block = telemetry_like({k: v[part] for k, v in out.items() if k != "estimates"}, fmax)
        loop.feed(block)
        assert loop.run(len(block["force"])) is block
        reference.measure(out["velocity_true"][part])
    assert loop.monitor.level == pytest.approx(reference.level, rel=1e-9)
    assert loop.monitor.cv == pytest.approx(reference.cv, rel=1e-9)
    assert loop.monitor.broken == reference.broken
    assert loop.fault is None


def test_a_real_device_is_judged_on_its_tachometer(bowed):
    _, out = bowed
    engine = RecordingEngine(["LOWPASS"])
    loop = EngineLoop(engine, {"LOWPASS": {}}, "LOWPASS", "strokes")
    block = telemetry_like({k: v for k, v in out.items() if k != "estimates"}, fmax=3.0)
    block["velocity_true"] = np.full_like(block["force"], np.nan)  # a real device has no true velocity
    loop.feed(block)
    loop.run(len(block["force"]))
    reference = StabilityMonitor(RATE)
    reference.measure(out["velocity_lvt"])
    assert loop.monitor.level == pytest.approx(reference.level, rel=1e-9) and loop.monitor.level > 0.0


def test_a_new_trial_starts_silent_and_hold_gives_settings_back():
    engine = RecordingEngine(["LVT", "KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "hold")
    assert engine.sent == [("set_fmax", 0.0), ("set_bowing", False), ("reset_string",),
                           ("set_gesture", "hold"), ("set_source", "KALLEV")]
    engine.sent.clear()
    loop.set_fmax(2.5)
    loop.set_bowing(True)
    loop.hold(True)
    loop.set_fmax(4.0)  # the runner moves on while held: nothing reaches the device
    assert engine.sent == [("set_fmax", 2.5), ("set_bowing", True), ("set_fmax", 0.0), ("set_bowing", False)]
    engine.sent.clear()
    loop.hold(False)
    assert engine.sent == [("set_fmax", 4.0), ("set_bowing", True)]


def test_fault_is_the_engines_latched_fault(bowed):
    fmax, out = bowed
    engine = RecordingEngine(["LOWPASS"])
    loop = EngineLoop(engine, {"LOWPASS": {}}, "LOWPASS", "strokes")
    engine.latched, engine.fault = True, "runaway: motor saturated"
    block = telemetry_like({k: v[:100] for k, v in out.items() if k != "estimates"}, fmax)
    loop.feed(block)
    loop.run(100)
    assert loop.fault == "runaway: motor saturated"


def test_refuses_a_condition_the_engine_does_not_run_and_a_short_feed():
    engine = RecordingEngine(["LVT"])
    with pytest.raises(ParameterError, match="KALLEV"):
        EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "strokes")
    loop = EngineLoop(engine, {"LVT": {}}, "LVT", "strokes")
    with pytest.raises(RuntimeError, match="fed 0"):
        loop.run(10)
