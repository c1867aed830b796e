"""scripts/pilot.py's command line (issue 30, item 6): the seed sets it reads and the input it refuses."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from pilot import BadInput, parse_sets  # noqa: E402


def test_sets_are_ranges_or_single_seeds():
    assert parse_sets("1-6,7-12") == [("1-6", [1, 2, 3, 4, 5, 6]), ("7-12", [7, 8, 9, 10, 11, 12])]
    assert parse_sets("0, 3-4") == [("0", [0]), ("3-4", [3, 4])]


@pytest.mark.parametrize("text", ["1-6,6-8", "a-3", "5-2", "1-2-3", "", "-1"])
def test_bad_sets_are_refused(text):
    with pytest.raises(BadInput):
        parse_sets(text)


@pytest.mark.parametrize("args, says", [(["--seeds", "1-6,5-9"], "seed 5 is in two sets"),
                                        (["--seeds", "6-1"], "runs backwards"),
                                        (["--protocol", "nope.toml"], "--protocol nope.toml: no such file"),
                                        (["--analyse-only"], "is not a folder")])
def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, args, says):
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "pilot.py"), "-o", str(tmp_path / "out"), *args],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2 and says in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_a_folder_with_something_in_it_is_refused(tmp_path):
    (tmp_path / "mine.txt").write_text("kept")
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "pilot.py"), "--seeds", "1", "-o", str(tmp_path)],
                          capture_output=True, text=True, cwd=ROOT)
    assert done.returncode == 2 and "not empty" in done.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["mine.txt"]
