"""``optimise --scheduler ADDRESS`` on a dask.distributed cluster finds the parameters local workers find."""

import tomllib

import pytest

from studyapp.cli import main
from tests.evaluation.conftest import synthetic_recording

distributed = pytest.importorskip(
    "distributed", reason="dask.distributed is not installed (pip install -e '.[distributed]')")

ESTIMATORS = ["LOWPASS", "LEASTSQ"]


def test_optimise_on_a_local_cluster_gives_the_local_workers_parameters(tmp_path):
    from studyapp.io.recording import save

    for i, fmax in enumerate((1.0, 7.7)):
        save(synthetic_recording(fmax, duration=0.3, seed=i), tmp_path / f"fmax_{fmax}.npz")
    common = [str(tmp_path), "--patience", "5", "--seed", "3", "--estimators", ",".join(ESTIMATORS), "--quiet"]
    assert main(["optimise", *common, "-o", str(tmp_path / "local.toml"), "--workers", "2"]) == 0
    # One in-process worker over TCP: the scheduler's own path (connect, submit, gather, close), light on CPU.
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp",
                                  dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://")
        assert main(["optimise", *common, "-o", str(tmp_path / "cluster.toml"),
                     "--scheduler", cluster.scheduler_address]) == 0
        # every parameter set ran on the cluster: the optimiser submits ``evaluate_sets(objective, sets)``,
        # one task per iteration and worker thread, each over its share of the recordings
        ran_on_cluster = cluster.scheduler.task_prefixes["evaluate_sets"].state_counts["memory"]
    local = tomllib.loads((tmp_path / "local.toml").read_text())
    remote = tomllib.loads((tmp_path / "cluster.toml").read_text())
    assert all(remote[name] == local[name] for name in ESTIMATORS)
    assert remote["objective"] == local["objective"]
    assert remote["provenance"]["iterations"] == local["provenance"]["iterations"] >= 5
    # the first sets, then at most one task per thread and iteration (fewer when every proposal was cached)
    assert 2 <= ran_on_cluster <= 2 * (local["provenance"]["iterations"] + 1)
