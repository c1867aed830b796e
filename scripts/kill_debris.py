"""What kills leave behind (issue 33, item 5): WAV files and shared memory, measured.

    PYTHONPATH=. python scripts/kill_debris.py OUT_FOLDER [SESSION_KILLS=50] [ENGINE_KILLS=10]

1. ``SESSION_KILLS`` headless sessions with ``--audio wav`` (the trials-only demo,
   simulated participant), each killed with its process group (SIGKILL) at a
   random moment 4-20 s after its start (seed 33): every ``audio*.wav`` left must
   open with ``wave`` (none empty), and no temporary (``.*`` but ``.lock``) remains.
2. ``ENGINE_KILLS`` runs of ``studyapp live --audio null --midi none``, each
   killed with its process group once its engine runs: the segments and
   semaphores each left in /dev/shm (``studyapp-<pid>-...``), then one more start,
   after which none of a dead process may remain.

Prints one JSON object. A measurement, never a test (it takes minutes).
"""

import json
import os
import random
import signal
import subprocess
import sys
import time
import wave
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.experiment.demo_protocol import trials_only_demo  # noqa: E402

ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


def _killed(argv, wait):
    process = subprocess.Popen([sys.executable, "-m", "studyapp", *argv], cwd=ROOT, env=ENV,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    wait(process)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    return process.pid


def _unreadable(path):
    try:
        with wave.open(str(path)) as f:
            f.getnframes()
    except (wave.Error, EOFError, OSError) as exc:
        return f"{path}: {exc}"
    return None


def _ours(pid=None):
    names = [n for n in os.listdir("/dev/shm") if n.startswith(("studyapp-", "sem.studyapp-"))]
    return [n for n in names if pid is None or f"-{pid}-" in n]


def _dead(name):
    try:
        os.kill(int(name.split("studyapp-")[1].split("-")[0]), 0)
    except ProcessLookupError:
        return True
    return False


def _engine_running(process):
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not any("-status-" in n for n in _ours(process.pid)):
        time.sleep(0.2)


def main(out, session_kills=50, engine_kills=10):
    out.mkdir(parents=True, exist_ok=True)
    protocol = trials_only_demo(out)
    results = out / "results"
    rng = random.Random(33)
    for i in range(session_kills):
        _killed(["run", "--protocol", str(protocol), "--participant", f"W{i:02d}", "--headless",
                 "--simulated-participant", "--audio", "wav", "--results", str(results)],
                lambda process: time.sleep(rng.uniform(4.0, 20.0)))
    wavs = sorted(results.rglob("*.wav")) if results.exists() else []
    left = []
    for _ in range(engine_kills):
        def wait(process):
            _engine_running(process)
            time.sleep(rng.uniform(0.5, 3.0))
        left.append(len(_ours(_killed(["live", "--audio", "null", "--midi", "none", "--seconds", "60"], wait))))
    subprocess.run([sys.executable, "-m", "studyapp", "live", "--audio", "null", "--midi", "none", "--seconds", "1"],
                   cwd=ROOT, env=ENV, capture_output=True)
    return {"session_kills": session_kills, "wav_files": len(wavs),
            "unreadable_or_empty": [w for w in map(_unreadable, wavs) if w],
            "temporaries": [str(p) for p in results.rglob(".*") if p.name != ".lock"] if results.exists() else [],
            "engine_kills": engine_kills, "left_by_each_kill": left,
            "left_after_the_next_start": [n for n in _ours() if _dead(n)]}


if __name__ == "__main__":
    args = sys.argv[1:]
    print(json.dumps(main(Path(args[0]), *map(int, args[1:3]))))
