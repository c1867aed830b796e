"""``optimise`` never writes over its inputs or an interrupted run's checkpoint (issue 33, item 6).

On main ``optimise DIR --checkpoint DIR/b.npz`` overwrote an input recording (the
folder, not its files, was checked), and a new ``optimise`` overwrote an
interrupted run's checkpoint after 30 s. A finished run marks its checkpoint
``complete``; a new run writes only over such a one."""

import json
import shutil

from tests.evaluation.conftest import fails_with_one_line


def test_a_checkpoint_over_a_recording_inside_an_input_folder_is_refused(short_recording, tmp_path, capsys):
    folder = tmp_path / "recs"
    folder.mkdir()
    shutil.copy(short_recording, folder / "b.npz")
    before = (folder / "b.npz").read_bytes()
    fails_with_one_line(capsys, ["optimise", str(folder), "-o", str(tmp_path / "p.toml"), "--checkpoint",
                                 str(folder / "b.npz")], "which this command reads or writes")
    assert (folder / "b.npz").read_bytes() == before


def test_an_interrupted_runs_checkpoint_is_kept_and_a_finished_ones_replaced(short_recording, tmp_path, capsys):
    from studyapp.cli import main

    out = tmp_path / "p.toml"
    checkpoint = tmp_path / "p.toml.checkpoint.json"
    argv = ["optimise", str(short_recording), "-o", str(out), "--estimators", "BDIFF", "--max-sets", "2", "--quiet"]
    assert main(argv) == 0
    finished = json.loads(checkpoint.read_text())
    assert finished["complete"] is True
    interrupted = {k: v for k, v in finished.items() if k != "complete"}
    checkpoint.write_text(json.dumps(interrupted))
    before = checkpoint.read_bytes()
    fails_with_one_line(capsys, argv, "the checkpoint of an interrupted run: allowed is --resume")
    assert checkpoint.read_bytes() == before
    checkpoint.write_text(json.dumps(finished))
    assert main(argv) == 0
