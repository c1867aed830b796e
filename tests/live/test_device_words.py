"""The device in words for the Apparatus panel (live/device_words.py)."""

from studyapp.live import device_words
from tests.live.test_rig_check import INFO


def test_the_handshake_calibration_and_latency_in_words():
    assert device_words.handshake(INFO) == ("studyapp emulator, serial EMU-0042; protocol v1, firmware 1.0; 5000 Hz; "
                                            "channels position (m), acceleration (m/s²), velocity (m/s)")
    assert device_words.calibration(INFO) == "handshake (the device's own gains)"
    assert device_words.calibration({**INFO, "calibration": "lab.toml [EMU-0042]"}) == "TOML file lab.toml [EMU-0042]"
    assert device_words.latency(INFO) == ("loop on the host: link latency 5 samples = 1.00 ms (packets of 1); "
                                          "round trip 0.05 ms median, 0.40 ms p99")
    assert device_words.late_risk(INFO) is None
    assert "exceeds the link latency" in device_words.late_risk({**INFO, "round_trip_ms": {"median": 1, "p99": 4.0}})
    assert "latency 0" in device_words.SIMULATED


def test_a_trials_health():
    counts = {"frames": 5000, "samples": 5000, "corrupt": 1, "lost": 0, "missing": 2, "late": 3, "faults": 0,
              "clamped": 0}
    assert device_words.health("trial 4", counts) == ("trial 4: 5000 frames, 5000 samples; 1 corrupt, 0 lost, "
                                                      "2 missing, 3 late, 0 faults, 0 clamped")


def test_a_held_pages_tag_is_named_by_its_step_never_as_a_negative_trial():
    # issue 41, item 12: the console read "trial -5: 5394 frames" for a page the engine held
    steps = {4: 2, 5: 3}  # engine tags 4 and 5 tagged the session's steps 3 and 4 (from 0: 2 and 3)
    assert device_words.step_words(-5, steps, 12) == "step 4 of 12"
    assert device_words.step_words(4, steps, 12) == "step 3 of 12"
    assert device_words.step_words(0, {}, 0) == "no step (the engine's start, or the preview)"
    assert device_words.step_words(7, {}, 0) == "trial 7"
    assert "-" not in device_words.step_words(-7, {}, 0)


def test_a_device_loop_says_loop_on_the_device_and_never_warns_of_late_forces():
    info = {**INFO, "protocol": 2, "loop": "device", "latency_samples": 0, "latency_ms": 0.0, "packet": 10,
            "lead_samples": 20, "keepalive_ms": 150, "round_trip_ms": {"median": 1.0, "p99": 9.0}}
    assert device_words.latency(info) == ("loop on the device: force from the same sample's sensors (latency 0, "
                                          "the paper's loop); telemetry in packets of 10, settings 4.0 ms ahead, "
                                          "keep-alive 150 ms; round trip 1.00 ms median, 9.00 ms p99")
    assert device_words.late_risk(info) is None
