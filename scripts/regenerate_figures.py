"""Regenerate every figure docs/ quotes: each documented generator, in order, dated (issue 30, item 6).

    make figures [CHECK=1]                                    # = the line below, OUT = figures/<UTC time>
    PYTHONPATH=. python scripts/regenerate_figures.py [-o OUT] [--only NAME ...] [--list] [--into-docs] [--check]

Runs the generators of ``GENERATORS`` (docs/figures.md lists each with the
figures it gives and where docs/ quotes them) one after the other, each
command exactly as docs/ states it, its outputs redirected into ``OUT/NAME/``.
The breakdown tables' commands are read from docs/breakdown.md's headers
("Generated on DATE by `studyapp breakdown ...`"), only their ``-o`` moved
into ``OUT``, so a table added or changed there is regenerated as stated.

For each generator ``OUT/NAME/output.md`` holds "Generated on DATE by
`COMMAND`" and what its commands printed, the line to paste beside a quoted
figure; ``OUT/figures.md`` sums up the run (date, commands, seconds, status).
Progress (generator, command, time so far) goes to stderr. ``--list`` prints
the generators and their commands, and runs nothing. ``--into-docs`` copies
the files a generator writes (PNGs, CSVs, docs/study's tables) over the ones
docs/ shows, once the generator has succeeded; figures quoted in prose are
updated by hand, and the quoted-figure tests (tests/test_quoted_*.py) fail
while one no longer matches the code on its quoted seeds.

``--check`` also compares each regenerated figure that has a measured
one-rounding spread with the one docs/ quotes (scripts/quoted_figures.py:
every seed's F_max of the breakdown tables, the paper's signals, the pilot's
table, the study's findings and objective) and says, per generator, whether
it holds or which figures moved beyond their spread; it exits 1 if one did.
It is the full-size check behind the quoted-figure tests, which run each
promise once at the smallest size that still checks it: run it before a
change of docs/ or of the model.

``OUT`` must be new or empty: nothing is written over.
"""

import argparse
import csv
import datetime
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import quoted_figures as qf

ROOT = Path(__file__).resolve().parents[1]
PY = "python"  # shown in the commands; run with this interpreter
SIN = "protocols/sinclair2014.toml"


@dataclass(frozen=True)
class Generator:
    """``steps``: commands (word lists; "{out}" is OUT/NAME, a word "glob:PATTERN" the sorted paths it matches
    then); ``files``: {file written under OUT/NAME: the docs/ file it regenerates}; ``quoted``: where docs/ quotes it."""
    name: str
    quoted: str
    steps: tuple
    files: dict = field(default_factory=dict)
    env: dict = field(default_factory=dict)


def breakdown_generators(text=None):
    """One generator per "Generated on DATE by `studyapp breakdown ...`" header of docs/breakdown.md."""
    text = (ROOT / "docs" / "breakdown.md").read_text() if text is None else text
    found = []
    for command in re.findall(r"Generated on \d{4}-\d\d-\d\d by `(studyapp breakdown [^`]+)`", text):
        words = shlex.split(command)
        gesture = words[words.index("--gesture") + 1] if "--gesture" in words else "strokes"
        rate = words[words.index("--rate") + 1] if "--rate" in words else "5000"
        windows = words[words.index("--windows") + 1] if "--windows" in words else "seconds"
        name = (f"breakdown-{gesture}" + ("" if float(rate) == 5000.0 else f"-{float(rate) / 1000:g}k")
                + ("-samples" if windows == "samples" else ""))
        out = words.index("-o") + 1 if "-o" in words else None
        if out is None:
            words += ["-o", f"{{out}}/{name}.md"]
        else:
            words[out] = f"{{out}}/{Path(words[out]).name}"
        found.append(Generator(name, "docs/breakdown.md (a table; docs/model.md quotes its medians)", (tuple(words),)))
    return found


def audio_session(n):
    return ("studyapp", "run", "--protocol", SIN, "--participant", f"SIM{n}", "--simulated-participant",
            "--headless", "--audio", "wav", "--seed", str(n), "--results", "{out}/results")


SEEDS = (0, 1, 2)  # the study over seeds (issue 30 item 5): Table 1 and the findings as median and range
STUDY = Generator(
    "study", "docs/evaluation.md (Against the paper: Table 1 and the findings, over seeds), docs/study/",
    (("studyapp", "simulate-set", "-o", "{out}/data/train"),
     ("studyapp", "simulate-set", "-o", "{out}/data/valid", "--validation"),
     *(("studyapp", "optimise", "glob:{out}/data/train/*.npz", "-o", f"{{out}}/s{seed}.toml", "--seed", str(seed),
        "--workers", "2") for seed in SEEDS),
     ("studyapp", "evaluate", "{out}/data/train", "--params", *(f"{{out}}/s{seed}.toml" for seed in SEEDS),
      "--validation", "{out}/data/valid", "-o", "{out}/results", "--compare-paper")),
    {"s0.toml": "docs/study/params.toml", "results/paper_comparison.csv": "docs/study/paper_comparison.csv",
     "results/findings.csv": "docs/study/findings.csv",
     **{f"s{seed}.toml": f"docs/study/seeds/q_s{seed}.toml" for seed in SEEDS},
     **{f"results/{name}": f"docs/study/seeds/{name}"
        for name in ("paper_comparison_seeds.csv", "metrics_seeds.csv", "findings_seeds.csv")}})

GENERATORS_AFTER_BREAKDOWN = (
    Generator("model-signals", "docs/model.md (The paper's signals; the pitches at 5, 20, 48 kHz)",
              ((PY, "scripts/model_figures.py", "--only-signals"),)),
    Generator("model-lvt", "docs/model.md (Breakdown while bowing: buzz, bands, the rise in dB), breakdown_strokes.png",
              ((PY, "scripts/model_figures.py", "--png", "{out}/breakdown_strokes.png", "--source", "LVT", "--seeds", "3"),),
              {"breakdown_strokes.png": "docs/breakdown_strokes.png"}),
    Generator("model-lowpass", "docs/model.md, breakdown_strokes_lowpass.png",
              ((PY, "scripts/model_figures.py", "--only-png", "--png", "{out}/breakdown_strokes_lowpass.png",
                "--source", "LOWPASS"),),
              {"breakdown_strokes_lowpass.png": "docs/breakdown_strokes_lowpass.png"}),
    Generator("string-pitch", "docs/model.md (Pitch / f0 at 1 and 5 kHz)",
              ((PY, "scripts/string_pitch.py", "--rates", "1000", "5000"),)),
    Generator("hiss-heard", "docs/model.md (Perception floors: the upper band on the handle and in the sound)",
              ((PY, "scripts/hiss_heard.py", "--fmax", "0.05,0.1,0.2,0.5,1,2,3"),)),
    Generator("pause-ring", "docs/model.md (The string between strokes), pause_ring.png",
              ((PY, "scripts/pause_ring.py", "--png", "{out}/pause_ring.png"),),
              {"pause_ring.png": "docs/pause_ring.png"}),
    Generator("stick-slip", "docs/model.md (The stick-slip against the paper), stick_slip_fig4.png",
              ((PY, "scripts/stick_slip.py", "--png", "{out}/stick_slip_fig4.png"),
               (PY, "scripts/stick_slip.py", "--f0", "70", "--fmax", "2.2,4.4,7.7,12.1")),
              {"stick_slip_fig4.png": "docs/stick_slip_fig4.png"}),
    Generator("seed-outliers", "docs/model.md (The seed outliers: BDIFF's pitch test)",
              ((PY, "scripts/seed_outliers.py", "--fmax", "0.05,6"),)),
    Generator("link-delay", "docs/devices.md (the link's delay tables), link_delay.png, link_delay_table.csv",
              ((PY, "scripts/link_delay_table.py", "--seeds", "5", "--rows", "latency,packet", "--out", "{out}"),),
              {"link_delay_table.csv": "docs/link_delay_table.csv", "link_delay.png": "docs/link_delay.png"}),
    Generator("audio-levels", "docs/engine.md (Levels)",
              tuple(audio_session(n) for n in (1, 2, 3))
              + ((PY, "scripts/audio_levels.py", "--rise", "--session", "glob:{out}/results/sinclair2014/SIM*/*"),)),
    Generator("audible-fmax", "docs/experiment.md (the audibility floor, 0.1 N)", ((PY, "scripts/audible_fmax.py"),)),
    Generator("device-panel", "docs/devices.md (the set-up panel on the emulator: LVT against the best estimators)",
              ((PY, "scripts/device_panel_screenshot.py", "{out}/console-device.png"),),
              {"console-device.png": "docs/console-device.png"}, {"QT_QPA_PLATFORM": "offscreen"}),
    STUDY,
    Generator("lowpass-sweep", "docs/evaluation.md (Why LOWPASS lands near 528 Hz), docs/lowpass_sweep.png",
              (("studyapp", "simulate-set", "-o", "{out}/data/train"),
               (PY, "scripts/lowpass_sweep.py", "{out}/data/train", "--params", "docs/study/params.toml",
                "-o", "{out}/lowpass_sweep.png")),
              {"lowpass_sweep.png": "docs/lowpass_sweep.png"}),
    Generator("kalman-conventions", "docs/estimators-kalman.md (Table 1's Kalman filters under each q convention)",
              (("studyapp", "simulate-set", "-o", "{out}/sim"), (PY, "scripts/kalman_conventions.py", "{out}/sim"))),
    Generator("pilot", "docs/experiment.md (The simulated participant: the in-silico pilot), docs/study/pilot.csv",
              ((PY, "scripts/pilot.py", "--seeds", "1-6,7-12", "-o", "{out}/pilot"),),
              {"pilot/pilot.csv": "docs/study/pilot.csv"}),
    Generator("lvdt-sensitivity", "docs/model.md (The sensors from their data sheets: breakdown and rho against the "
              "LVDT's bandwidth and noise), lvdt_sensitivity.png, lvdt_sensitivity.csv",
              ((PY, "scripts/lvdt_sensitivity.py", "-o", "{out}/lvdt"),),
              {"lvdt/lvdt_sensitivity.png": "docs/lvdt_sensitivity.png",
               "lvdt/lvdt_sensitivity.csv": "docs/lvdt_sensitivity.csv"}),
    Generator("blas-kernels", "docs/reproducibility.md (The same bits under every BLAS kernel)",
              ((PY, "scripts/blas_kernels.py"),)),
    Generator("sensitivity", "docs/reproducibility.md (Sensitivity to one rounding); scripts/quoted_figures.py's spreads",
              ((PY, "scripts/sensitivity.py", "-o", "{out}/sensitivity", "--parts", "breakdown,signals,pilot,study",
                "--seeds", "10", "--tables", "strokes,hold"),
               (PY, "scripts/sensitivity.py", "-o", "{out}/sensitivity-48k", "--parts", "breakdown", "--seeds", "10",
                "--tables", "strokes-48k", "--sources", "LVT"))),
)


def generators():
    return breakdown_generators() + list(GENERATORS_AFTER_BREAKDOWN)


def shown(words, out):
    """The command as docs/ states it (``studyapp ...`` or ``PYTHONPATH=. python scripts/...``), writing into ``out``."""
    text = shlex.join(w.replace("{out}", str(out)).removeprefix("glob:") for w in words)
    return f"PYTHONPATH=. {text}" if words[0] == PY else text


def resolve(words, out):
    """The command to run: placeholders filled, globs expanded, python and studyapp this checkout's."""
    argv = []
    for word in words:
        word = word.replace("{out}", str(out))
        argv += sorted(glob.glob(word[5:])) if word.startswith("glob:") else [word]
    if argv[0] == PY:
        return [sys.executable] + argv[1:]
    if argv[0] == "studyapp":
        return [sys.executable, "-m", "studyapp"] + argv[1:]
    return argv


def run_generator(gen, out, log):
    """Run ``gen``'s steps in ``out``; True when every step exits 0. Each step's output goes to ``log``."""
    env = dict(os.environ, **gen.env)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    for words in gen.steps:
        print(f"figures:   $ {shown(words, out)}", file=sys.stderr, flush=True)
        log.write(f"$ {shown(words, out)}\n\n```\n")
        log.flush()
        done = subprocess.run(resolve(words, out), cwd=ROOT, env=env, stdout=log, stderr=subprocess.PIPE, text=True)
        log.write("```\n\n")
        if done.returncode != 0:
            log.write(f"exit {done.returncode}: {done.stderr.strip()[-2000:]}\n")
            return False
    return True


def check_breakdown(gen, folder):
    """The regenerated table against docs/breakdown.md's with the same command, seed by seed."""
    (words,) = gen.steps
    made = folder / Path(words[-1].replace("{out}", str(folder))).name
    ((_, command, new_rows),) = qf.breakdown_tables(made.read_text())
    args = qf.breakdown_settings(command)
    for _, quoted_command, rows in qf.breakdown_tables((ROOT / "docs" / "breakdown.md").read_text()):
        quoted = qf.breakdown_settings(quoted_command)
        if vars(quoted) | {"output": None} == vars(args) | {"output": None}:  # the same settings, defaults filled
            return qf.compare_breakdown(rows, new_rows, args.gesture, args.rate)
    return [f"no table of docs/breakdown.md has the settings of {command}"]


def check_signals(gen, folder):
    quoted = qf.quoted_signals(qf.signals_paragraph((ROOT / "docs" / "model.md").read_text()))
    return qf.compare_signals(quoted, qf.printed_signals((folder / "output.md").read_text()))


def check_pilot(gen, folder):
    _, _, quoted = qf.pilot_table((ROOT / "docs" / "experiment.md").read_text())
    _, _, new = qf.pilot_table((folder / "pilot" / "pilot.md").read_text())
    return qf.compare_pilot(quoted, new)


def check_study(gen, folder):
    with open(folder / "results" / "findings.csv", newline="") as f:
        new = list(csv.DictReader(f))
    with open(ROOT / "docs" / "study" / "findings.csv", newline="") as f:
        quoted = list(csv.DictReader(f))
    return [f"finding {a['finding']!r}: {a['verdict']} against the quoted {b['verdict']}" for a, b in zip(new, quoted)
            if a["verdict"] != b["verdict"] and a["finding"] not in qf.FLIPPING_FINDINGS]


def check_of(gen):
    """The comparison of ``gen``'s figures with docs/ (None: no figure of it has a measured spread)."""
    if gen.name.startswith("breakdown-"):
        return check_breakdown
    return {"model-signals": check_signals, "pilot": check_pilot, "study": check_study}.get(gen.name)


def main(argv=None):
    every = generators()
    names = [g.name for g in every]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="figures", help="a new or empty folder (default figures/)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="these generators only (see --list)")
    parser.add_argument("--list", action="store_true", help="list the generators and their commands; run nothing")
    parser.add_argument("--into-docs", action="store_true", help="copy each generated file over the docs/ file it regenerates")
    parser.add_argument("--check", action="store_true",
                        help="compare the regenerated figures with docs/ within their measured one-rounding spread")
    args = parser.parse_args(argv)
    unknown = [n for n in args.only or [] if n not in names]
    if unknown:
        parser.exit(2, f"regenerate_figures: error: --only {unknown[0]}: no such generator; allowed: {', '.join(names)}\n")
    chosen = [g for g in every if not args.only or g.name in args.only]
    if args.list:
        for g in chosen:
            print(f"{g.name}: {g.quoted}")
            for words in g.steps:
                print(f"    {shown(words, Path('OUT') / g.name)}")
        return 0
    out = Path(args.output)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        parser.exit(2, f"regenerate_figures: error: -o {out}: not empty; allowed is a new or empty folder (nothing is written over)\n")
    today = datetime.date.today().isoformat()
    started, summary, failed = time.monotonic(), [], []
    for i, gen in enumerate(chosen, 1):
        print(f"figures: [{i}/{len(chosen)}] {gen.name} ({time.monotonic() - started:.0f} s so far)", file=sys.stderr, flush=True)
        folder = out / gen.name
        folder.mkdir(parents=True)
        t0 = time.monotonic()
        with open(folder / "output.md", "w") as log:
            commands = "`, `".join(shown(w, folder) for w in gen.steps)
            log.write(f"Generated on {today} by `{commands}`.\n\n")
            ok = run_generator(gen, folder, log)
        seconds = time.monotonic() - t0
        status = "ok" if ok else "FAILED"
        if ok and args.check:
            compare = check_of(gen)
            problems = compare(gen, folder) if compare else None
            status = "ok, not compared (no measured spread)" if problems is None else (
                "ok, holds" if not problems else f"MOVED ({len(problems)})")
            with open(folder / "output.md", "a") as log:
                log.write("".join(f"- moved beyond its spread: {p}\n" for p in problems or []))
            for p in problems or []:
                print(f"figures:   moved beyond its spread: {p}", file=sys.stderr, flush=True)
            if problems:
                failed.append(gen.name)
        if ok and args.into_docs:
            for made, doc in gen.files.items():
                shutil.copyfile(folder / made, ROOT / doc)
        summary.append(f"| {gen.name} | {today} | {status} | {seconds:.0f} | `{commands}` |")
        print(f"figures:   {gen.name} {status if ok else 'FAILED (see ' + str(folder / 'output.md') + ')'} in {seconds:.0f} s",
              file=sys.stderr, flush=True)
        if not ok:
            failed.append(gen.name)
    (out / "figures.md").write_text("| generator | date | status | seconds | commands |\n| --- | --- | --- | --- | --- |\n"
                                    + "\n".join(summary) + "\n")
    print(f"figures: {len(chosen) - len(failed)} of {len(chosen)} generators ran; outputs in {out}"
          + (f"; failed: {', '.join(failed)}" if failed else ""), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
