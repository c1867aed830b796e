"""Every estimator stays finite and bounded at the extremes.

10^6 samples at 1, 5, 40 and 96 kHz for position steps, 2 m/s ramps
(triangle waves within the 2.2 cm travel), full-scale 2.2 cm jumps and pure
sensor noise, with Table 1's parameters and with every parameter at the low
end and at the high end of its allowed range.

Bounded means: no estimate exceeds ten times the largest velocity a 2.2 cm
jump in one sample can show (0.022 m * rate), plus a margin for the
acceleration and velocity inputs. A blow-up (a state that grows without
bound) fails this long before 10^6 samples.
"""

import numpy as np
import pytest

from studyapp import estimators
from studyapp.estimators.spec import NYQUIST_FRACTION, Q_CONVENTIONS

N = 1_000_000
RATES = [1000.0, 5000.0, 40_000.0, 96_000.0]
TRAVEL = 0.022


def signals(rate):
    t = np.arange(N) / rate
    rng = np.random.default_rng(int(rate))
    period = 2 * TRAVEL / 2.0  # 2 m/s up, 2 m/s down
    tri = TRAVEL / 2 - np.abs((t % period) / period * 2 * TRAVEL - TRAVEL)
    return {
        "steps": np.where((t % 1.0) < 0.5, 0.0, 1e-3),
        "ramps": tri,
        "jumps": np.where((t % 0.2) < 0.1, -TRAVEL / 2, TRAVEL / 2),
        "noise": rng.normal(0.0, 15e-6, N),
    }


def params_at(end, rate):
    """Every estimator with every numeric parameter at one end of its range."""
    out = {}
    for name in estimators.names():
        spec = estimators.describe(name)
        chosen = {}
        for p in spec["parameters"]:
            if p["kind"] == "choice":
                chosen[p["name"]] = Q_CONVENTIONS[0 if end == "low" else 1]
            elif end == "low":
                chosen[p["name"]] = p["low"]
            else:
                high = p["high"]
                if p.get("below_nyquist"):
                    high = min(high, NYQUIST_FRACTION * rate)
                chosen[p["name"]] = high
        if name == "LEASTSQ" and end == "low":
            chosen["window"] = chosen["order"] + 1
        out[name] = chosen
    return out


def table1_at(rate):
    """Table 1's parameters, with cut-offs above the rate's limit capped (2,254 Hz does not exist at 1 kHz)."""
    out = {}
    for name in estimators.names():
        out[name] = {
            p["name"]: min(p["default"], NYQUIST_FRACTION * rate)
            for p in estimators.describe(name)["parameters"]
            if p.get("below_nyquist") and p["default"] > NYQUIST_FRACTION * rate
        }
    return out


@pytest.fixture(scope="module", params=RATES, ids=lambda r: f"{r / 1000:g}kHz")
def rate_signals(request):
    return request.param, signals(request.param)


@pytest.mark.parametrize("setting", ["table1", "low", "high"])
def test_finite_and_bounded(rate_signals, setting):
    rate, sigs = rate_signals
    chosen = table1_at(rate) if setting == "table1" else params_at(setting, rate)
    rng = np.random.default_rng(7)
    acc = rng.normal(0.05, 0.22, N)  # accelerometer noise with a small bias
    vel = rng.normal(0.0, 0.115e-3, N)
    bound = 10 * TRAVEL * rate + 1e3
    for signal_name, x in sigs.items():
        bank = estimators.Bank(rate, chosen)
        out = bank.process(x, acc, vel)
        finite = np.isfinite(out).all(axis=1)
        assert finite.all(), f"{signal_name}: non-finite output from {np.array(bank.names)[~finite]}"
        peak = np.max(np.abs(out), axis=1)
        worst = int(np.argmax(peak))
        assert peak[worst] < bound, f"{signal_name}: {bank.names[worst]} reached {peak[worst]:.3g} m/s"
