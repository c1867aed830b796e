"""Practice trials never reach the statistics: the export's ``practice`` rows are left out by default."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from studyapp.analysis.responses import load_responses
from studyapp.analysis.study import analyse
from studyapp.cli import main
from studyapp.errors import InputDataError
from tests.analysis.conftest import synthetic_responses


def with_practice(participants=5):
    """Real rows (practice False) plus practice rows far off every real value: F_max 150 N for
    LVT and 0.01 N for FOAW (reversing their order), and ratings upside down."""
    real = synthetic_responses(participants=participants, trials=3, seed=4).assign(practice=False)
    practice = []
    for participant in real.participant.unique():
        for condition, fmax in (("FOAW", 150.0), ("LVT", 0.01)):
            practice.append((participant, "s1", "adjustment", condition, 1, fmax, np.nan, "t", "h1", True))
        for condition, rating in (("LVT", 1.0), ("LEVANT", 0.0)):
            practice.append((participant, "s1", "rating", condition, 1, 1.0, rating, "t", "h1", True))
    frame = pd.concat([real, pd.DataFrame(practice, columns=real.columns)], ignore_index=True)
    return frame.sample(frac=1.0, random_state=1).reset_index(drop=True), real


def test_practice_rows_enter_neither_the_rank_sums_nor_the_spearman_inputs(tmp_path):
    frame, real = with_practice()
    path = tmp_path / "responses.csv"
    frame.to_csv(path, index=False)
    responses, _ = load_responses(path)
    assert len(responses) == len(real) and not responses.practice.any()
    study = analyse(responses)
    real_adjustment = real[real.task == "adjustment"]
    for condition, samples in study.adjustment.groups.items():
        expected = real_adjustment[real_adjustment.condition == condition].fmax.to_numpy()
        assert sorted(samples) == sorted(expected)
    # the pooled test of LVT against FOAW: scipy on the real trials alone
    lvt = real_adjustment[real_adjustment.condition == "LVT"].fmax.to_numpy()
    foaw = real_adjustment[real_adjustment.condition == "FOAW"].fmax.to_numpy()
    row = study.adjustment.wilcoxon.set_index(["condition_a", "condition_b"]).loc[("LVT", "FOAW")]
    reference = stats.mannwhitneyu(lvt, foaw, method="auto", use_continuity=False)
    assert row.p_raw == pytest.approx(reference.pvalue, rel=1e-9)
    # each participant's Spearman rho: scipy on their real medians against the real global medians
    global_median = real_adjustment.groupby("condition").fmax.median()
    for _, spearman_row in study.participant_spearman.iterrows():
        mine = real_adjustment[real_adjustment.participant == spearman_row.participant]
        own = mine.groupby("condition").fmax.median()
        rho = stats.spearmanr(own.to_numpy(), global_median[own.index].to_numpy()).statistic
        assert spearman_row.rho == pytest.approx(rho, abs=1e-12)
    assert study.missing.empty  # practice rows are not counted as extra trials either


def test_include_practice_keeps_them_and_a_bad_flag_is_named(tmp_path):
    frame, real = with_practice(participants=3)
    path = tmp_path / "responses.csv"
    frame.to_csv(path, index=False)
    responses, _ = load_responses(path, include_practice=True)
    assert len(responses) == len(frame) and responses.practice.sum() == len(frame) - len(real)
    frame["practice"] = frame["practice"].astype(object)
    frame.loc[7, "practice"] = "maybe"
    frame.to_csv(path, index=False)
    with pytest.raises(InputDataError, match="column 'practice' at line 9 is 'maybe'; allowed: True, False"):
        load_responses(path)


def test_analyse_cli_keeps_practice_only_when_asked(tmp_path, capsys):
    frame, real = with_practice(participants=3)
    path = tmp_path / "responses.csv"
    frame.to_csv(path, index=False)
    assert main(["analyse", str(path), "-o", str(tmp_path / "all"), "--include-practice"]) == 0
    assert f"3 participants, {len(frame)} responses" in capsys.readouterr().err
