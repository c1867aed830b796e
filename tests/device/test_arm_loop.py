"""The loop cross-compiled for a Cortex-M7 and run under qemu (scripts/arm_loop.py, firmware/arm) against the same
loop on this machine: every sample's outputs and the arrays after the last, bit for bit, computed in the same run.

Needs the Debian packages of scripts/system-deps-arm.txt (``make arm`` installs them, then runs this file with
STUDYAPP_ARM=1; make test and CI skip the qemu runs, saying so). The bad-input test runs everywhere.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import arm_insn_mix  # noqa: E402
import arm_loop  # noqa: E402

MISSING = arm_loop.missing_tools()
# qemu runs minutes of CPU (6 min at load 8, 2026-11-28): make arm asks for these (STUDYAPP_ARM=1), make test not,
# even on a machine where an earlier make arm left the toolchain
ASKED = os.environ.get("STUDYAPP_ARM") == "1"
needs_arm = pytest.mark.skipif(bool(MISSING) or not ASKED,
                               reason=f"the ARM toolchain is not installed (missing {', '.join(MISSING)}: make arm "
                               f"installs scripts/system-deps-arm.txt)" if MISSING else "make arm runs these (qemu)")


@pytest.fixture(scope="module")
def elf(tmp_path_factory):
    return arm_loop.build(tmp_path_factory.mktemp("arm-build"))


@pytest.fixture(scope="module")
def protocol():
    return arm_loop.conditions()


@needs_arm
@pytest.mark.parametrize("rate, condition, fmax, seed", [(5000.0, "KALFOAW", 1.0, 0), (20000.0, "LEVANT", 4.0, 1),
                                                         (96000.0, "LVT", 0.5, 2), (3000.0, "FOAW", 20.0, 3)])
def test_arm_equals_x86_and_the_numba_loop_that_recorded_the_stream(elf, protocol, tmp_path, rate, condition, fmax,
                                                                    seed):
    r = arm_loop.compare_one(elf, rate, 0.05, condition, fmax, seed, protocol[1], 6, tmp_path)
    assert r["n"] == round(0.05 * rate)
    assert {name: v[0] for name, v in r["rows"].items()} == {name: 0 for name in r["rows"]}
    assert r["final_words_differing"] == 0
    assert {name: v[0] for name, v in r["numba"].items()} == {"force": 0, "string_velocity": 0, "estimates": 0}
    assert np.any(r["arm_out"][0] != 0.0)  # the loop bowed: a force to compare


@needs_arm
def test_bad_sensor_samples_take_the_same_guard_and_fault_path_on_both(elf, protocol, tmp_path):
    """NaN, inf and out-of-bound samples: the estimators' guard replaces them, the loop latches its fault."""
    rate = 5000.0
    stream, _, _ = arm_loop.record(rate, 0.04, "KALLEV", 1.0, 0, protocol[1])
    x, a, v = (s.copy() for s in stream)
    v[50] = np.inf
    x[60] = 2.0  # beyond the guard's 1 m
    x[120] = np.nan  # latches the sensor fault: the force is 0 from here on
    r = arm_loop.compare_stream(elf, lambda: arm_loop.new_loop(rate, "KALLEV", 1.0, 0, protocol[1]).control.arrays,
                                (x, a, v), 6, tmp_path)
    assert {name: v[0] for name, v in r["rows"].items()} == {name: 0 for name in r["rows"]}
    assert r["final_words_differing"] == 0
    assert np.all(r["arm_out"][0, 120:] == 0.0) and np.any(r["arm_out"][0, :120] != 0.0)


@needs_arm
def test_control_events_act_at_their_sample_on_both(elf, protocol, tmp_path):
    """The host's CONTROL frames as the device applies them before a sample: F_max, source, bowing, force scale,
    a string reset; ARM and x86 equal bit for bit, and each event seen where it acts."""
    from studyapp.model import control

    rate = 5000.0
    stream, _, names = arm_loop.record(rate, 0.1, "KALFOAW", 2.0, 0, protocol[1])
    peak = arm_loop.new_loop(rate, "KALFOAW", 2.0, 0, protocol[1]).string.peak_friction()
    events = [(100, control.C_GAIN, 5.0 / peak), (150, control.C_SOURCE, names.index("LEVANT")),
              (200, control.C_BOWING, 0.0), (250, control.C_BOWING, 1.0), (250, arm_loop.RESET_STRING, 0.0),
              (300, control.C_FORCE_SCALE, 0.5), (350, control.C_SOURCE, -2.0), (400, control.C_GAIN, 20.0 / peak)]
    r = arm_loop.compare_stream(elf, lambda: arm_loop.new_loop(rate, "KALFOAW", 2.0, 0, protocol[1]).control.arrays,
                                stream, 6, tmp_path, events)
    assert {name: v[0] for name, v in r["rows"].items()} == {name: 0 for name in r["rows"]}
    assert r["final_words_differing"] == 0
    force, source = r["arm_out"][0], r["arm_out"][1]
    assert np.all(force[200:250] == 0.0) and np.any(force[250:300] != 0.0)  # the bow lifted, then down again
    assert np.array_equal(source[350:], stream[2][350:])  # LVT drives the bow from sample 350
    assert np.array_equal(source[150:350], r["arm_est"][names.index("LEVANT"), 150:350])
    assert np.abs(force[400:]).max() > np.abs(force[:100]).max()  # F_max 20 N against 2 N


@needs_arm
def test_systick_under_icount_counts_instructions(elf, protocol, tmp_path):
    """The calibration loop's 2 x 100000 instructions (subs, bne) read as 2^S ns / 40 ns each (25 MHz SysTick)."""
    stream, _, _ = arm_loop.record(5000.0, 0.01, "LVT", 1.0, 0, protocol[1])
    for shift in (5, 6, 7):
        r = arm_loop.compare_stream(elf, lambda: arm_loop.new_loop(5000.0, "LVT", 1.0, 0, protocol[1]).control.arrays,
                                    stream, shift, tmp_path)
        insns, ticks, empty, reps, no_sample = r["meta"]
        assert insns == 200000 and reps == 64 and no_sample == 1
        # measured 2.5, 1.25 and 1.9 instructions over (shifts 5, 6, 7): a tick's rounding at each of the four reads
        assert abs(ticks * 40 / 2 ** shift - insns) <= 4
        assert 5 <= empty / reps * 40 / 2 ** shift <= 20  # the window: two reads, four loads, the call, the return
        assert 1000 < r["insn_median"] < 20000


@needs_arm
@pytest.mark.slow
def test_the_trace_counts_what_systick_counts(elf, protocol, tmp_path):
    """Two independent counts of sl_sample's instructions: SysTick under icount, the window's own cost (an empty
    call's) subtracted, and qemu's log of every executed instruction from sl_sample's entry to its return."""
    for rate, condition in ((5000.0, "KALFOAW"), (20000.0, "LVT"), (96000.0, "LEVANT")):
        stream, _, _ = arm_loop.record(rate, 50 / rate, condition, 1.0, 0, protocol[1])
        make = lambda: arm_loop.new_loop(rate, condition, 1.0, 0, protocol[1]).control.arrays  # noqa: E731
        counted = arm_loop.compare_stream(elf, make, stream, 6, tmp_path)["insn_mean"]
        n, by_class, _, _, _, _ = arm_insn_mix.mix(elf, stream, make, tmp_path, model=False)
        traced = sum(by_class.values()) / n
        # a tick (0.625 instructions) of rounding in the empty calls' mean and in each sample's reading
        assert abs(counted - traced) < 1.0, (rate, condition, counted, traced)


@pytest.mark.parametrize("script, args, says", [
    ("arm_loop.py", ["--conditions", "NOPE"], "--conditions 'NOPE': allowed are"),
    ("arm_loop.py", ["--rates", "abc"], "--rates 'abc'"),
    ("arm_loop.py", ["--seconds", "0"], "--seconds 0.0: allowed is"),
    ("arm_loop.py", ["--rates", "1000"], "--rates '1000': rate 1000 Hz with f0"),
    ("arm_loop.py", ["--fmax", "-1"], "--fmax: fmax = -1.0: allowed is"),
    ("arm_insn_mix.py", ["--condition", "NOPE"], "--condition 'NOPE': allowed are"),
    ("arm_insn_mix.py", ["--samples", "0"], "--samples 0: allowed is"),
])
def test_bad_input_is_one_line_and_exit_2(script, args, says):
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / script), *args], capture_output=True, text=True,
                          cwd=ROOT)
    assert done.returncode == 2 and says in done.stderr
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1


def test_the_in_order_model_against_closed_forms():
    """scripts/arm_insn_mix.py's model: independent integer instructions pair (n/2 cycles), a chain of dependent
    double multiplies waits 7 cycles a link, double loads issue alone, a double add pairs with an integer one."""
    cycles = arm_insn_mix.in_order_cycles
    independent = [("add", f"r{2 * (i % 4)}, r{2 * (i % 4) + 1}, #1") for i in range(100)]
    assert cycles(independent) == 50
    assert cycles([("vmul.f64", "d0, d0, d1")] * 10) == 9 * 7 + 1
    assert cycles([("vldr", f"d{i % 8}, [r3, #{8 * i}]") for i in range(10)]) == 10
    assert cycles([("vadd.f64", "d0, d1, d2"), ("add", "r0, r1, #1")] * 10) == 10
    assert cycles([("vadd.f64", "d0, d1, d2"), ("vadd.f64", "d3, d4, d5")] * 10) == 20  # one FP op a cycle
    assert cycles([("vmla.f64", "d7, d5, d6")] * 3) == 2 * 11 + 1  # the accumulator is a source
    # the branch waits a cycle for the flags, then pairs with the next subs: 1 + 5 cycles
    assert cycles([("subs", "r3, #1"), ("bne.n", "1b")] * 5) == 6


def test_the_classes_and_the_flags_of_a_mnemonic():
    assert arm_insn_mix.split_mnemonic("lsls") == ("lsl", True, False)  # not lsl + the condition "ls"
    assert arm_insn_mix.split_mnemonic("movls") == ("mov", False, True)
    assert arm_insn_mix.split_mnemonic("bics") == ("bic", True, False)
    assert arm_insn_mix.classify("vpop", "{d8-d13}")[1:3] == ("alone", 6)
    assert arm_insn_mix.classify("vdiv.f64", "d0, d1, d2")[0] == "double divide and square root"
    assert arm_insn_mix.classify("bic", "r1, r2")[0] == "integer and other"
    assert arm_insn_mix.classify("pop", "{r4, pc}")[0] == "branches"
    assert arm_insn_mix.classify("ldr", "r0, [pc, #20]")[0] == "integer and other"


def test_the_arm_build_compiles_what_the_host_build_links():
    """firmware/arm/Makefile's LOOP names the C files of studyapp/device/c_loop.py's build: a file added there and
    not here would leave the ARM build short of a symbol."""
    from studyapp.device import c_loop

    line = next(ln for ln in (ROOT / "firmware" / "arm" / "Makefile").read_text().splitlines()
                if ln.startswith("LOOP ="))
    assert sorted(f"{name}.c" for name in line.split("=", 1)[1].split()) == \
        sorted(s for s in c_loop.sources() if s.endswith(".c"))
