"""The numba cache is keyed by the compiled sources' contents, not by where the clone lies (issue 31, item 8).

Two copies of the package in two temporary folders, their files with fresh
modification times (as a clone has), share one cache home: a kernel compiled
by the first is loaded, not compiled, by the second.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from studyapp import numba_cache

ROOT = Path(__file__).resolve().parents[1]

# one small kernel, called once; what its dispatcher found in the cache
PROBE = """
import json, numpy as np
from studyapp.estimators.history import fill
fill(np.zeros(3), 1.0)
print(json.dumps({"hits": sum(fill.stats.cache_hits.values()), "misses": sum(fill.stats.cache_misses.values()),
                  "dir": __import__("os").environ["NUMBA_CACHE_DIR"]}))
"""


def _clone(target):
    # shutil.copy, not copy2: new modification times, as a fresh clone has
    shutil.copytree(ROOT / "studyapp", target / "studyapp", copy_function=shutil.copy,
                    ignore=shutil.ignore_patterns("__pycache__"))
    return target


def _probe(clone, cache_home):
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env.update(PYTHONPATH=str(clone), XDG_CACHE_HOME=str(cache_home))
    run = subprocess.run([sys.executable, "-c", PROBE], cwd=clone, env=env, capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_a_second_clone_of_the_same_sources_loads_the_first_clones_kernels(tmp_path):
    first, second = _clone(tmp_path / "a"), _clone(tmp_path / "b")
    home = tmp_path / "cache"
    made = _probe(first, home)
    again = _probe(second, home)
    assert made["misses"] == 1 and made["hits"] == 0  # compiled here (a new cache)
    assert Path(made["dir"]) == Path(again["dir"])  # one source hash: the same folder
    assert again == {**made, "hits": 1, "misses": 0}  # loaded, not compiled again


def test_the_cache_folder_of_a_file_is_named_relative_to_the_package():
    assert numba_cache.relative_folder(ROOT / "studyapp" / "model" / "loop.py") == "studyapp/model"
    assert numba_cache.relative_folder(ROOT / "scripts" / "audio_levels.py") is None
