"""Does the C loop's equality test see a one-operation change? Each mutant of firmware/studyapp_loop.c, tried.

    PYTHONPATH=. python scripts/c_loop_mutants.py

For each mutant (one operation regrouped or rewritten, the same value in exact arithmetic but not in
double; or one check left out) a copy of the sources is made with it, and
tests/device/test_c_loop.py's comparisons run on the copy; a mutant the tests pass is "missed". The
unchanged copy is run first and must pass. Prints one line per mutant and exits 1 if any was missed.
A check of the tests, never a test itself (it takes minutes: hypothesis hunts for each difference).
"""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LOOP = "firmware/studyapp_loop.c"
TESTS = ["tests/device/test_c_loop.py", "-k", "bit_for_bit or sees_bowing"]

MUTANTS = (
    ("the interpolation as (1 - f) a + f b",
     "return a + frac * (buf[ib] - a);", "return (1.0 - frac) * a + frac * buf[ib];"),
    ("the force regrouped, G (u g)",
     "f = -ctl[SL_C_GAIN] * u * ctl[SL_C_FORCE_SCALE];", "f = -ctl[SL_C_GAIN] * (u * ctl[SL_C_FORCE_SCALE]);"),
    ("the string velocity regrouped",
     "*v_string = v_h + u;", "*v_string = bridge_refl + (nut_refl + u);"),
    ("the mean square as (1 - alpha) ms + alpha f^2",
     "s[SL_LS_MS] += p[SL_LP_RMS_ALPHA] * (f * f - s[SL_LS_MS]);",
     "s[SL_LS_MS] = (1.0 - p[SL_LP_RMS_ALPHA]) * s[SL_LS_MS] + p[SL_LP_RMS_ALPHA] * (f * f);"),
    ("rho's 1 / t^4 as 1 / t^2 / t^2",
     "double r = 1.0 / (t2 * t2);", "double r = 1.0 / t2 / t2;"),
    ("a division as a product by the reciprocal",
     "o->string_velocity = v_string / ctl[SL_C_SCALE];", "o->string_velocity = v_string * (1.0 / ctl[SL_C_SCALE]);"),
    ("the accelerometer left out of the sensor check",
     "if (bad(x_m) || bad(v_m) || bad(a_m)) latch", "if (bad(x_m) || bad(v_m)) latch"),
)


def passes(tree):
    env = dict(os.environ, PYTHONPATH=str(tree))
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider", *TESTS], cwd=tree,
                       env=env, capture_output=True, text=True, timeout=1800)
    return r.returncode == 0


def main():
    source = (ROOT / LOOP).read_text()
    missed = 0
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "tree"
        for part in ("studyapp", "firmware", "tests", "pyproject.toml"):
            copy = shutil.copytree if (ROOT / part).is_dir() else shutil.copy
            copy(ROOT / part, tree / part)
        if not passes(tree):
            print("the unchanged copy fails its tests: nothing to compare against", file=sys.stderr)
            return 1
        for name, old, new in MUTANTS:
            if source.count(old) != 1:
                print(f"{name}: its line is no longer in {LOOP} once; update the script", file=sys.stderr)
                return 1
            (tree / LOOP).write_text(source.replace(old, new))
            caught = not passes(tree)
            missed += not caught
            print(f"{'caught' if caught else 'MISSED'}: {name}", flush=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
