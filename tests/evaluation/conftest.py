"""Synthetic recordings for the evaluation tests (no closed loop needed).

The signal is ``studyapp.synthetic.stick_slip``: a stick-slip-like velocity
with the paper's sensors (Sec. 4.2), the LVT reference band-limited at 500 Hz.
"""

import pytest

from studyapp.synthetic import stick_slip as _stick_slip


def stick_slip(rate=5000.0, duration=1.0, f0=110.0, ripple=0.02, seed=0):
    return _stick_slip(rate, duration, f0=f0, ripple=ripple, f_stroke=0.7, seed=seed)


def synthetic_recording(fmax, rate=5000.0, duration=1.0, seed=0):
    """A ``studyapp.io.recording.Recording`` of the synthetic signal; the ripple grows with F_max."""
    from studyapp.io.recording import Recording

    sig = stick_slip(rate, duration, ripple=0.01 + 0.004 * fmax, seed=seed)
    return Recording(rate, sig, {"fmax": float(fmax), "rate": rate, "source": "synthetic", "seed": seed})


@pytest.fixture(scope="session")
def synthetic():
    return stick_slip


@pytest.fixture(scope="session")
def short_recording(tmp_path_factory):
    """A 0.3 s synthetic recording at F_max = 1 N, saved as .npz (for command-line tests)."""
    from studyapp.io.recording import save

    path = tmp_path_factory.mktemp("short_recording") / "fmax_1.npz"
    save(synthetic_recording(1.0, duration=0.3), path)
    return path


def fails_with_one_line(capsys, argv, match):
    """``studyapp argv`` exits 2 with one line on stderr that names ``match``, and no traceback."""
    from studyapp.cli import main

    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("studyapp: error:") and match in lines[0]
    assert "Traceback" not in err
