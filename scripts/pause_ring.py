"""The string between strokes, before and after the nut segment kept its share of the loss (issue 42, item 7).

Prints, for each F_max and seed, the ring at f0 / (1 - beta) in the pauses of
the strokes (studyapp/model/pause_ring.py: dB against the bowed note, the
largest over the pauses, in the audio and in the handle's velocity; and its
decay in dB/s, the median over the pauses; negative: it grows), with STK's
lumped losses ("lumped", the string until 2026-11-29) and with the shared
losses ("shared", bowed_string.py). With ``--png`` it draws one pause's audio
and its spectrum both ways. docs/model.md ("The string between strokes")
quotes its output.
"""

import argparse

import numpy as np

from studyapp.model import pause_ring


def row(rate, fmax, seed, source, nut_loss):
    block, string = pause_ring.run_strokes(rate, fmax, seed, source, nut_loss=nut_loss)
    levels = pause_ring.ring_levels(block, rate, string.f0, string.beta)
    pauses, _ = pause_ring.strokes_phases(block["t"])
    f_ring = string.f0 / (1.0 - string.beta)
    decay = np.median([pause_ring.ring_decay(block["audio"][a:e], rate, f_ring) for a, e in pauses])
    return levels["audio"][0].max(), levels["velocity_true"][0].max(), np.median(levels["audio"][1]), decay


def draw(path, rate=5000.0, fmaxes=(2.0, 5.0), seed=40, source="LVT"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(len(fmaxes), 2, figsize=(11, 3.6 * len(fmaxes)), squeeze=False)
    for row_ax, fmax in zip(ax, fmaxes):
        for nut_loss, label in ((False, "lumped (before)"), (True, "shared (after)")):
            block, string = pause_ring.run_strokes(rate, fmax, seed, source, nut_loss=nut_loss)
            t = block["t"]
            m = (t >= 0.6) & (t < 0.86)
            row_ax[0].plot(t[m], block["audio"][m], lw=0.7, label=label)
            pauses, _ = pause_ring.strokes_phases(t)
            a, e = pauses[2]
            x = block["audio"][a:e] - block["audio"][a:e].mean()
            w = np.hanning(x.size)
            spec = np.abs(np.fft.rfft(x * w, 8 * x.size)) * 2 / w.sum()
            row_ax[1].plot(np.fft.rfftfreq(8 * x.size, 1 / rate), 20 * np.log10(spec + 1e-12), label=label)
        row_ax[1].axvline(string.f0 / (1.0 - string.beta), color="k", ls=":", label="f0 / (1 - beta)")
        row_ax[0].set_title(f"{source}, strokes at {fmax:g} N, {rate:g} Hz, seed {seed}", fontsize=9)
        row_ax[0].set_xlabel("t (s): a stroke, then its pause")
        row_ax[0].set_ylabel("audio")
        row_ax[1].set_xlabel("Hz (the third pause)")
        row_ax[1].set_ylabel("dB (audio units)")
        row_ax[1].set_xlim(0, 2000)
        for a_ in row_ax:
            a_.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rates", default="5000")
    p.add_argument("--fmax", default="1,2,5,8")
    p.add_argument("--seeds", default="40,41,42")
    p.add_argument("--source", default="LVT")
    p.add_argument("--png")
    a = p.parse_args(argv)
    print("| rate (Hz) | F_max (N) | seed | losses | ring in the audio (dB, max) | in the handle (dB, max) | "
          "ring (Hz) | decay (dB/s, median) |")
    print("|---|---|---|---|---|---|---|---|")
    for rate in (float(r) for r in a.rates.split(",")):
        for fmax in (float(f) for f in a.fmax.split(",")):
            for seed in (int(s) for s in a.seeds.split(",")):
                for nut_loss in (False, True):
                    audio, handle, hz, decay = row(rate, fmax, seed, a.source, nut_loss)
                    print(f"| {rate:g} | {fmax:g} | {seed} | {'shared' if nut_loss else 'lumped'} | {audio:.1f} | "
                          f"{handle:.1f} | {hz:.0f} | {decay:.0f} |", flush=True)
    if a.png:
        draw(a.png)


if __name__ == "__main__":
    main()
