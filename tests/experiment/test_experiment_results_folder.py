"""One study, one folder: the results folder does not depend on the working directory (issue 31 item 6)."""

from pathlib import Path

from studyapp.cli import main
from studyapp.experiment.protocol import load_protocol
from studyapp.experiment.results_folder import absolute, default_results, used_rows, used_rows_text
from studyapp.experiment.session import Session

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "protocols" / "demo.toml"


def enrol(results, participant, simulated=False):
    session = Session.create(load_protocol(DEMO), participant, results,
                             apparatus={"participant": "simulated" if simulated else "human"})
    session.close()


def test_the_default_is_absolute_and_the_same_from_every_folder(tmp_path, monkeypatch):
    monkeypatch.delenv("STUDYAPP_RESULTS", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert default_results() == tmp_path / "data" / "studyapp" / "results"
    monkeypatch.setenv("STUDYAPP_RESULTS", str(tmp_path / "lab"))
    assert default_results() == tmp_path / "lab"
    monkeypatch.chdir(tmp_path)
    assert absolute("here") == tmp_path / "here" and absolute(None) == tmp_path / "lab"


def test_plan_without_results_gives_the_same_row_from_any_folder_and_names_the_rows_used(tmp_path, monkeypatch,
                                                                                          capsys):
    lab = tmp_path / "lab"
    monkeypatch.setenv("STUDYAPP_RESULTS", str(lab))
    enrol(lab, "P01")
    enrol(lab, "SIM01", simulated=True)
    assert used_rows(lab / "demo", simulated=False) == {0: ["P01"]}
    assert used_rows_text(lab / "demo", simulated=True) == "order rows used by simulated participants: 0 (SIM01)"
    sheets = []
    for where in ("a", "b"):
        (tmp_path / where).mkdir()
        monkeypatch.chdir(tmp_path / where)
        assert main(["plan", "--protocol", str(DEMO), "--participant", "P02"]) == 0
        sheets.append(capsys.readouterr().out)
        assert not (tmp_path / where / "results").exists()
    assert sheets[0] == sheets[1]
    assert "order row **1** of 6" in sheets[0]
    assert f"Results folder: `{lab}`; order rows used by real participants: 0 (P01)" in sheets[0]
