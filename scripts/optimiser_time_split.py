"""Where a whole optimiser run spends its time: a cProfile of ``optimise`` in one process, by part.

    PYTHONPATH=. python scripts/optimiser_time_split.py DIR [--patience 30] [--seed 0]

Runs the paper's optimiser (thirteen estimators, ``--workers 1``: every set in
this process, so the profile sees all the work) on the recordings of DIR and
splits its time into the parts the optimiser is made of:

- compile: loading or compiling the estimators and the compiled loops (``warm_up``);
- estimator runs: the estimators over the recordings (``kernels``), without the
  filter design and parameter checks of ``create``, which are a part of their own;
- delay and error: ``metric.Reference.measure`` (its FFTs also on their own);
- search and normalisation: proposing sets, checking them, the objective sum;
- checkpoints: the state snapshot every iteration and the file every 30 s.

Process overhead (tasks sent to worker processes, their waiting) is not in a
one-process profile: compare the CPU and wall time of the command with
``--workers 2`` against this total. Times are the profiler's (it inflates
small Python calls more than compiled loops).
"""

import argparse
import cProfile
import pstats
import tempfile
import time
from pathlib import Path

from studyapp.evaluation.dataset import RawObjectives, RecordingFiles, expand_paths, load_takes, warm_up
from studyapp.evaluation.executors import InlineExecutor
from studyapp.evaluation.optimiser import Optimiser
from studyapp.evaluation.space import PAPER_ESTIMATORS, Space

# part -> functions (file suffix, function name) whose cumulative time it is; later parts are
# subtracted from earlier ones where they nest (create runs inside the estimator runs' batch).
PARTS = {
    "compile (warm_up)": [("dataset.py", "warm_up")],
    "estimator runs": [("batch.py", "estimates")],
    "  of which create (design, checks)": [("estimators/__init__.py", "create")],
    "delay and error": [("metric.py", "measure")],
    "  of which FFTs": [("scipy/fft/_basic_backend.py", "rfft"), ("scipy/fft/_basic_backend.py", "irfft")],
    "search (propose, report)": [("search.py", "propose"), ("search.py", "report")],
    "normalisation (objective sum)": [("normalisation.py", "step")],
    "checkpoints (state, save)": [("optimiser.py", "state"), ("optimiser.py", "_save")],
}


def cumulative(stats, suffix, function):
    total = 0.0
    for (path, _, name), (_, _, _, cum, _) in stats.stats.items():
        if name == function and path.replace("\\", "/").endswith(suffix):
            total += cum
    return total


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings")
    parser.add_argument("--patience", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    paths = tuple(expand_paths([args.recordings]))
    rate = min(t.rate for t in load_takes(paths))
    spaces = {name: Space(name, rate) for name in PAPER_ESTIMATORS}
    objective = RawObjectives(RecordingFiles(paths, "lvt", 0.02, tuple(PAPER_ESTIMATORS)))
    profile = cProfile.Profile(time.process_time)  # CPU time: the machine is shared
    started = time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        profile.enable()
        warm_up(tuple(PAPER_ESTIMATORS), rate, True)
        optimiser = Optimiser(spaces, objective, InlineExecutor(), patience=args.patience, seed=args.seed,
                              checkpoint=Path(tmp) / "checkpoint.json")
        result = optimiser.run()
        profile.disable()
    total = time.process_time() - started
    stats = pstats.Stats(profile)
    print(f"optimise in one process, patience {args.patience}, seed {args.seed}: {result.iterations} iterations, "
          f"{result.evaluated} sets, {total:.1f} s CPU (under the profiler)")
    print(f"{'part':<36} {'s':>8} {'%':>6} {'ms/set':>8}")
    accounted = 0.0
    for part, functions in PARTS.items():
        seconds = sum(cumulative(stats, suffix, function) for suffix, function in functions)
        if not part.startswith(" "):
            accounted += seconds
        print(f"{part:<36} {seconds:>8.2f} {100 * seconds / total:>6.1f} {1e3 * seconds / result.evaluated:>8.2f}")
    rest = total - accounted
    print(f"{'rest (loading, progress, Python)':<36} {rest:>8.2f} {100 * rest / total:>6.1f} "
          f"{1e3 * rest / result.evaluated:>8.2f}")


if __name__ == "__main__":
    main()
