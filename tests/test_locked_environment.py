"""requirements.lock is what this venv has: every distribution pinned to its exact version, each with a hash.

``make setup`` installs the lock with ``pip --require-hashes`` (Makefile), so two fresh installs get the
same versions; these tests check that the lock parses, that it pins exactly the distributions of the
venv running the tests (``importlib.metadata``; studyapp itself is installed from the work tree), that
it satisfies pyproject.toml's requirements (a dependency added there without ``make lock`` fails here),
and that the Makefile re-installs when the lock changes.
"""

import importlib.metadata
import platform
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.version import Version

ROOT = Path(__file__).resolve().parent.parent
LOCK = ROOT / "requirements.lock"
LINE = re.compile(r"([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s\\]+)((?:\s+--hash=sha256:[0-9a-f]{64})+)")


def canonical(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def parse(text):
    """{canonical name: version}; every requirement must be ``name==version`` with sha256 hashes."""
    pinned = {}
    for entry in re.sub(r"\\\n", " ", text).splitlines():
        entry = entry.strip()
        if not entry or entry.startswith("#"):
            continue
        match = LINE.fullmatch(entry)
        assert match, f"not pinned with a hash: {entry!r}"
        assert canonical(match.group(1)) not in pinned, f"pinned twice: {match.group(1)}"
        pinned[canonical(match.group(1))] = match.group(2)
    return pinned


@pytest.fixture(scope="module")
def lock():
    text = LOCK.read_text()
    locked_for = re.search(r"^# platform: (.+)$", text, re.M).group(1)
    here = (f"{platform.python_implementation()} {sys.version_info.major}.{sys.version_info.minor} "
            f"{platform.system()} {platform.machine()}")
    if locked_for != here:
        pytest.skip(f"the lock is for {locked_for}, this Python is {here} (README: another platform)")
    return parse(text)


def test_every_line_is_pinned_with_a_hash():
    pinned = parse(LOCK.read_text())
    assert len(pinned) > 40 and {"numpy", "scipy", "numba", "llvmlite", "pandas", "pip", "setuptools"} <= set(pinned)


def test_the_lock_pins_exactly_what_this_venv_has(lock):
    installed = {canonical(d.metadata["Name"]): d.version for d in importlib.metadata.distributions()}
    installed.pop("studyapp")
    assert sorted(set(installed) - set(lock)) == [], "installed but not in the lock"
    assert sorted(set(lock) - set(installed)) == [], "in the lock but not installed"
    assert {name: v for name, v in installed.items() if lock[name] != v} == {}


def test_the_lock_satisfies_pyproject(lock):
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    wanted = [*project["dependencies"], *(r for extra in project["optional-dependencies"].values() for r in extra)]
    marker_env = {**default_environment(), "extra": ""}
    checked = 0
    for text in wanted:
        requirement = Requirement(text)
        if canonical(requirement.name) == "studyapp" or (requirement.marker and not requirement.marker.evaluate(marker_env)):
            continue
        assert canonical(requirement.name) in lock, f"{text}: not in the lock (run make lock)"
        assert Version(lock[canonical(requirement.name)]) in requirement.specifier, text
        checked += 1
    assert checked >= 15


def test_the_stamp_depends_on_the_lock_and_installs_it_with_hashes():
    database = subprocess.run(["make", "-pn", "setup"], cwd=ROOT, capture_output=True, text=True,
                              stdin=subprocess.DEVNULL).stdout
    rule = re.search(r"^\.venv/\.installed: (.*)$", database, re.M)
    assert rule and "requirements.lock" in rule.group(1).split()
    recipe = subprocess.run(["make", "-n", "-B", "setup"], cwd=ROOT, capture_output=True, text=True,
                            stdin=subprocess.DEVNULL).stdout
    assert "pip install -q --require-hashes -r requirements.lock" in recipe
    assert "pip install -q --no-deps --no-build-isolation -e ." in recipe


def test_another_platform_is_refused_in_one_line(tmp_path):
    other = tmp_path / "requirements.lock"
    other.write_text(re.sub(r"^# platform: .+$", "# platform: CPython 3.99 Plan9 mips", LOCK.read_text(), flags=re.M))
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "locked_environment.py"), "check", str(other)],
                          capture_output=True, text=True, stdin=subprocess.DEVNULL)
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "locked for CPython 3.99 Plan9 mips" in done.stderr
    assert "pip install -e '.[test]'" in done.stderr and "make lock" in done.stderr
