"""Issue 31 item 4's target: Esc then Resume in the first adjustment trial, N tries, counting the responses above
the trial's largest heard F_max and the stalls.

    PYTHONPATH=. QT_QPA_PLATFORM=offscreen python scripts/esc_resume_tries.py [--tries 10] [--first-seed 1]
        [--protocol protocols/demo.toml] [--interrupt esc|watchdog] [--results DIR]

Each try is a new session of the simulated participant (participant SIMESC01, SIMESC02, ..., seed
``first-seed + k``) in one console (offscreen Qt, no audio, no MIDI, as ``studyapp run --protocol
protocols/demo.toml --participant SIMESC --simulated-participant --audio null --midi none``): once the knob of
its first adjustment trial reaches position 12 to 40 (drawn per try), Esc on the participant's window and
Resume (``--interrupt watchdog``: the engine's worker stopped by SIGSTOP until the watchdog trips, then Resume,
which starts a new engine), then the session is waited for (tests/gui/interrupted_session.py says how it is
judged). Prints one line per try and the counts.
"""

import argparse
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from tests.gui.interrupted_session import INTERRUPTS, play_interrupted  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tries", type=int, default=10)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--protocol", default="protocols/demo.toml")
    parser.add_argument("--interrupt", choices=INTERRUPTS, default="esc")
    parser.add_argument("--results", default=None, help="where the sessions go (default: a temporary folder)")
    args = parser.parse_args()

    from studyapp.gui.app import application
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    app = application()
    # the watchdog's 0.5 s as in the GUI tests: a shared machine must not trip it unasked
    controller = SessionController(audio="null", midi="none", hang_timeout=0.5)
    console = Console(controller)
    console.resize(1400, 900)
    console.show()
    assert console.choose_protocol(args.protocol), console.setup.error.text()
    results = Path(args.results or tempfile.mkdtemp(prefix="esc_resume_"))
    stalls = above = 0
    try:
        for k in range(args.tries):
            seed = args.first_seed + k
            at = int(np.random.default_rng([seed, 31]).integers(12, 41))
            outcome = play_interrupted(console, app, results, f"SIMESC{k + 1:02d}", seed, args.interrupt, at)
            stalls += bool(outcome.stalled)
            above += len(outcome.above_heard)
            sim_errors = [e for e in outcome.errors if "simulated participant" in e]
            print(f"try {k + 1} seed {seed} {args.interrupt} at knob {at}: {outcome.state}"
                  f"{' STALLED: ' + outcome.stalled if outcome.stalled else ''}, {outcome.responses} adjustment "
                  f"responses, {len(outcome.above_heard)} above the heard F_max, restarts {outcome.restarts}"
                  f"{', errors: ' + '; '.join(sim_errors) if sim_errors else ''}", flush=True)
    finally:
        console.shut_down()
    print(f"{args.tries} tries ({args.interrupt}, {args.protocol}): {above} responses above the trial's largest "
          f"heard F_max, {stalls} stalls; sessions in {results}")
    return 1 if stalls or above else 0


if __name__ == "__main__":
    sys.exit(main())
