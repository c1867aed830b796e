"""Fixtures for the analysis tests.

Qt must find the offscreen platform before anything imports it, so the
environment is set here, at collection time.
"""

import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

EXPORT_COLUMNS = ["participant", "session", "task", "condition", "trial", "fmax", "rating", "time", "protocol_hash"]
# what `studyapp analyse` must write (issues 7 and 12): table -> columns, and figure stems (PNG + SVG)
SIGNED_RANK = ["condition_a", "condition_b", "statistic", "p_value", "p_holm", "effect_size", "significant"]
TABLES = {
    "wilcoxon_adjustment.csv": ["condition_a", "condition_b", "statistic", "p_value", "significant"],
    "wilcoxon_rating.csv": ["condition_a", "condition_b", "statistic", "p_value", "significant"],
    "summary_adjustment.csv": ["condition", "n", "median", "q1", "q3"],
    "summary_rating.csv": ["condition", "n", "median", "q1", "q3"],
    "spearman_participants.csv": ["participant", "rho", "p_value"],
    "friedman.csv": ["task", "statistic", "p_value", "n_participants"],
    "signed_rank_adjustment.csv": SIGNED_RANK,
    "signed_rank_rating.csv": SIGNED_RANK,
}
# with --evaluation
PERCEPTUAL = ["comparison", "metric", "n", "rho", "p_value", "paper_rho", "conditions"]
FIGURES = ["fig7_adjustment", "fig8_rating", "fig9_scatter"]

# A synthetic study shaped like the paper's (Sec. 8.4, Figs. 7-8): breakdown
# F_max per condition (N) and noisiness (0 best) per condition. Not measured data.
SYNTHETIC_FMAX = {
    "LVT": 20.0, "LEVANT": 11.0, "KALPOS": 10.0, "LOWPASS": 10.0, "KALLEV": 9.5,
    "LEVANTLP": 9.0, "LEASTSQ": 8.0, "KALFOAW": 7.0, "FOAW": 5.0,
}
SYNTHETIC_NOISINESS = {
    "LVT": 0.0, "KALLEV": 0.2, "LOWPASS": 0.35, "KALPOS": 0.4, "LEASTSQ": 0.5,
    "LEVANTLP": 0.55, "FOAW": 0.7, "LEVANT": 1.0,
}


def synthetic_responses(participants=9, trials=6, seed=0, drop=()):
    """A synthetic export (the contract's columns) of a paper-like study.

    Each participant scales every F_max by a personal factor (inter-subject
    spread) and each trial jitters it (intra-subject spread). ``drop`` lists
    (participant, condition, trial) adjustment responses to leave out.
    """
    rng = np.random.default_rng(seed)
    rows = []
    for p in range(participants):
        pid = f"P{p + 1:02d}"
        scale = np.exp(rng.normal(0.0, 0.25))
        for condition, noisiness in SYNTHETIC_NOISINESS.items():
            rating = noisiness if noisiness in (0.0, 1.0) else float(np.clip(noisiness + rng.normal(0, 0.08), 0, 1))
            rows.append((pid, "s1", "rating", condition, 1, 1.0, rating, "2024-05-01T10:00:00", "h1"))
        for condition, fmax in SYNTHETIC_FMAX.items():
            for trial in range(1, trials + 1):
                if (pid, condition, trial) in drop:
                    continue
                value = round(fmax * scale * np.exp(rng.normal(0.0, 0.1)), 2)
                rows.append((pid, "s1", "adjustment", condition, trial, value, np.nan, "2024-05-01T10:10:00", "h1"))
    return pd.DataFrame(rows, columns=EXPORT_COLUMNS)


@pytest.fixture
def synthetic_csv(tmp_path):
    """Path of a synthetic responses.csv where P03 lacks FOAW trials 5 and 6."""
    path = tmp_path / "responses.csv"
    synthetic_responses(drop={("P03", "FOAW", 5), ("P03", "FOAW", 6)}).to_csv(path, index=False)
    return path
