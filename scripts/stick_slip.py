"""The data set's stick-slip against the paper's Sec. 6 and Fig. 4 (issue 42, "What to build" item 4).

On the training set's recordings (data_set.py: LVT in the loop, 7 s at
5 kHz, the recording's own seed) it prints, per F_max:

- slips: ``velocity_lvt`` high-passed at 100 Hz (2nd-order Butterworth), RMS
  in mm/s, and the true velocity high-passed the same way, its peak-to-peak
  over each stroke's cruise (median over cruises; the slip amplitude a plot
  like Fig. 4 shows);
- max |dv/dt| of ``velocity_lvt`` (m/s^2; the paper's "about 200 m/s^2 for
  the larger gain settings", Sec. 6.4), of the true velocity, and the
  accelerometer's max |a| (flat to 10 kHz: it sees what the LVT's 500 Hz
  band rounds off);
- LEVANT at Table 1's C = 19.7 on the recording's position: the share of
  samples where the true |dv/dt| exceeds C, the longest such run (ms), and
  the longest drift, a run where LEVANT's error smoothed over 1 ms is above
  3 times its RMS on the F_max 0 recording (no friction: switching noise and
  the sensors' alone): the paper's Fig. 4b shows one of 7 ms (t = 3.480-3.487 s
  at 7.67 N).

With ``--png`` it draws Fig. 4's kind of plot at 7.7 N (true velocity, LVT,
LEVANT, LEVANTLP over 40 ms of a stroke, the samples where |dv/dt| > C marked)
and the F_max sweep of the figures above. docs/model.md ("Stick-slip against
the paper") quotes its output.
"""

import argparse
import tomllib
from pathlib import Path

import numpy as np
from scipy import signal

from studyapp.estimators import create
from studyapp.model.data_set import PAPER_FMAX, TRAINING
from studyapp.model.pause_ring import intervals, strokes_phases
from studyapp.model.simulate import simulate

RATE = 5000.0
TABLE1 = tomllib.loads((Path(__file__).resolve().parents[1] / "protocols" / "sinclair2014.toml").read_text())["estimators"]
SMOOTH = 0.001  # s: LEVANT's error averaged over this before the drift test (takes the chattering out)
DRIFT_FACTOR = 3.0


F0 = [None]  # the string's pitch (Hz; None: calibration.F0), set by --f0


def recording(fmax):
    index = PAPER_FMAX.index(fmax)
    return simulate(fmax, rate=RATE, duration=7.0, source="LVT", seed=TRAINING["seed"] * 1000 + index,
                    f0=F0[0]).columns


def levant(columns, name="LEVANT"):
    params = {k: v for k, v in TABLE1[name].items()}
    return create(name, RATE, **params).process(columns["position"])


def longest(mask):
    runs = [e - a for a, e in intervals(mask)]
    return 1e3 * max(runs, default=0) / RATE


def smoothed_error(c):
    """LEVANT's error against the true velocity, averaged over SMOOTH (the chattering out)."""
    m = int(SMOOTH * RATE)
    return np.convolve(levant(c) - c["velocity_true"], np.ones(m) / m, "same")


def rest_rms():
    """RMS of the smoothed error on the F_max 0 recording, after its first 0.2 s (LEVANT's start from zero)."""
    return float(np.sqrt(np.mean(smoothed_error(recording(0))[int(0.2 * RATE):] ** 2)))


def figures(fmax, rest):
    c = recording(fmax)
    t = np.arange(c["velocity_lvt"].size) / RATE
    _, cruises = strokes_phases(t)
    hp = signal.sosfilt(signal.butter(2, 100.0, "high", fs=RATE, output="sos"), c["velocity_lvt"])
    v = c["velocity_true"]
    v_hp = signal.sosfilt(signal.butter(2, 100.0, "high", fs=RATE, output="sos"), v)
    ripple = np.median([np.ptp(v_hp[a + int(0.01 * RATE):e]) for a, e in cruises])
    a_true = np.abs(np.diff(v)) * RATE
    over = a_true > TABLE1["LEVANT"]["c"]
    drift = np.abs(smoothed_error(c)) > DRIFT_FACTOR * rest
    return {"fmax": fmax, "hp_rms_mm_s": 1e3 * np.sqrt(np.mean(hp ** 2)), "ripple_mm_s": 1e3 * ripple,
            "dvdt_lvt": float(np.max(np.abs(np.diff(c["velocity_lvt"]))) * RATE), "dvdt_true": float(a_true.max()),
            "acc": float(np.max(np.abs(c["acceleration"]))),
            "over_c_pct": 100.0 * over.mean(), "over_c_ms": longest(over), "drift_ms": longest(drift)}


def fig4(path, fmax=7.7, start=3.47, span=0.04):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    c = recording(fmax)
    t = np.arange(c["velocity_lvt"].size) / RATE
    m = (t >= start) & (t < start + span)
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    ax[0].plot(t[m], 1e3 * c["velocity_true"][m], "k", lw=1.5, label="true")
    ax[0].plot(t[m], 1e3 * c["velocity_lvt"][m], label="LVT")
    ax[0].plot(t[m], 1e3 * levant(c)[m], lw=0.8, label=f"LEVANT C={TABLE1['LEVANT']['c']}")
    ax[0].plot(t[m], 1e3 * levant(c, "LEVANTLP")[m], label="LEVANTLP")
    ax[0].set_ylabel("velocity (mm/s)")
    ax[0].legend(fontsize=8)
    a = np.r_[0.0, np.diff(c["velocity_true"])] * RATE
    ax[1].plot(t[m], a[m], "k")
    ax[1].axhline(TABLE1["LEVANT"]["c"], color="r", ls="--")
    ax[1].axhline(-TABLE1["LEVANT"]["c"], color="r", ls="--", label="+-C")
    ax[1].set_ylabel("true dv/dt (m/s^2)")
    ax[1].set_xlabel("t (s)")
    ax[1].legend(fontsize=8)
    fig.suptitle(f"Fig. 4's kind at F_max {fmax:g} N (training recording, LVT in the loop)")
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--fmax", default="1.1,2.2,4.4,5.5,7.7,9.9,12.1", help="F_max values (N) of the data set")
    p.add_argument("--png", help="write Fig. 4's kind of plot here")
    p.add_argument("--f0", type=float, help="the string's pitch (Hz; default calibration.F0)")
    a = p.parse_args(argv)
    F0[0] = a.f0
    rest = rest_rms()
    print(f"LEVANT's error at F_max 0, smoothed over {1e3 * SMOOTH:g} ms: {1e3 * rest:.2f} mm/s RMS; drift: above "
          f"{DRIFT_FACTOR:g} times that")
    print("| F_max (N) | LVT > 100 Hz (mm/s RMS) | true ripple (mm/s p-p) | max dv/dt LVT (m/s^2) | true | "
          "accelerometer | true > C (% of samples) | longest run > C (ms) | longest LEVANT drift (ms) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for f in (float(x) for x in a.fmax.split(",")):
        r = figures(f, rest)
        print(f"| {f:g} | {r['hp_rms_mm_s']:.2f} | {r['ripple_mm_s']:.1f} | {r['dvdt_lvt']:.0f} | {r['dvdt_true']:.0f} | "
              f"{r['acc']:.0f} | {r['over_c_pct']:.2f} | {r['over_c_ms']:.1f} | {r['drift_ms']:.1f} |", flush=True)
    if a.png:
        fig4(a.png)


if __name__ == "__main__":
    main()
