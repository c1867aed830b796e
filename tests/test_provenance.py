"""studyapp.provenance's parts: the commit of a checkout (dirty or not, none outside one) and the CPU model."""

import subprocess

from studyapp.provenance import commit, cpu_model, environment


def git(folder, *args):
    return subprocess.run(["git", "-C", str(folder), *args], capture_output=True, text=True, check=True).stdout.strip()


def test_commit_of_a_checkout_clean_then_dirty_and_of_a_folder_inside_one(tmp_path):
    git(tmp_path, "init", "-q")
    (tmp_path / "a.txt").write_text("one\n")
    git(tmp_path, "add", "a.txt")
    git(tmp_path, "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "one")
    head = git(tmp_path, "rev-parse", "HEAD")
    (tmp_path / "untracked.txt").write_text("not part of the tree\n")
    assert commit(tmp_path) == head
    (tmp_path / "a.txt").write_text("two\n")
    assert commit(tmp_path) == head + "-dirty"
    inside = tmp_path / "venv" / "site-packages"  # a package installed into a venv that lies in some repository
    inside.mkdir(parents=True)
    assert commit(inside) == "unknown"


def test_cpu_model_is_the_first_model_name(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) Platinum 8375C\n\n"
                       "processor\t: 1\nmodel name\t: Intel(R) Xeon(R) Platinum 8375C\n")
    assert cpu_model(cpuinfo) == "Intel(R) Xeon(R) Platinum 8375C"


def test_environment_is_a_copy_for_the_caller():
    mine = environment()
    mine["numpy_version"] = "changed"
    assert environment()["numpy_version"] != "changed"


def test_a_studyapp_setting_from_the_environment_is_recorded(monkeypatch):
    """A run nudged one rounding step (STUDYAPP_NUDGE, model/nudge.py) must not pass for a plain one."""
    from studyapp import provenance

    monkeypatch.setenv("STUDYAPP_NUDGE", "1")
    monkeypatch.delenv("STUDYAPP_GROUP_SHARED", raising=False)
    provenance._environment.cache_clear()
    try:
        info = provenance.environment()
    finally:
        provenance._environment.cache_clear()
    assert info["env_STUDYAPP_NUDGE"] == "1"
    assert "env_STUDYAPP_GROUP_SHARED" not in info
