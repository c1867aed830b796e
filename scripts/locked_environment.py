"""The lock file: exact versions and hashes of everything ``make setup`` installs.

``write LOCK`` (``make lock``) resolves ``.[test]`` from pyproject.toml's ranges, plus pip and setuptools
(``make setup`` installs the package itself with ``--no-build-isolation``, so the build's setuptools is
locked too), in a throwaway virtual environment of the Python running this script, with that venv's
pip and the machine's configured indexes: ``pip install --dry-run --ignore-installed --report``
installs nothing and reports the file pip chose for each distribution with its SHA-256. Every line of
the lock is ``name==version --hash=sha256:...``, for ``pip install --require-hashes -r LOCK``.

The files pip chose are the wheels of one platform: the header's ``# platform:`` line names it (the
Python implementation, its major.minor, the OS and the machine), and ``check LOCK`` refuses, in one
line and with exit code 2, a Python that does not match it, before pip would fail on a hash.
"""

import json
import platform
import re
import subprocess
import sys
import tempfile
import venv
from datetime import datetime, timezone
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PROJECT = "studyapp"
BUILD_TOOLS = ("pip", "setuptools")


def canonical(name):
    """PEP 503's normalised name: ``PySide6_Essentials`` -> ``pyside6-essentials``."""
    return re.sub(r"[-_.]+", "-", name).lower()


def this_platform():
    """The platform a lock is valid for: what decides which wheel pip picks for this Python."""
    return (f"{platform.python_implementation()} {sys.version_info.major}.{sys.version_info.minor} "
            f"{platform.system()} {platform.machine()}")


def lock_platform(text):
    match = re.search(r"^# platform: (.+)$", text, re.M)
    return match.group(1).strip() if match else None


def pins(text):
    """{canonical name: (version, [sha256, ...])} of a lock file's text (continuation lines joined)."""
    joined = re.sub(r"\\\n", " ", text)
    found = {}
    for line in joined.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        match = re.fullmatch(r"([A-Za-z0-9][A-Za-z0-9._-]*)==(\S+)((?:\s+--hash=sha256:[0-9a-f]{64})*)", line)
        if not match:
            raise ValueError(f"not a pinned, hashed requirement: {line!r}")
        found[canonical(match.group(1))] = (match.group(2), re.findall(r"sha256:([0-9a-f]{64})", match.group(3)))
    return found


def resolve(python_dir):
    """The report's install list: pip's choice for ``.[test]`` plus the build tools, nothing installed."""
    with tempfile.TemporaryDirectory(prefix="studyapp-lock-") as scratch:
        env_dir = Path(scratch) / "venv"
        venv.EnvBuilder(with_pip=True).create(env_dir)
        report = Path(scratch) / "report.json"
        subprocess.run([str(env_dir / python_dir / "python"), "-m", "pip", "install", "--quiet", "--dry-run",
                        "--ignore-installed", "--report", str(report), f"{ROOT}[test]", *BUILD_TOOLS],
                       check=True, stdin=subprocess.DEVNULL)
        return json.loads(report.read_text())


def lines(report):
    rows = []
    for item in report["install"]:
        name, version = item["metadata"]["name"], item["metadata"]["version"]
        if canonical(name) == PROJECT:
            continue
        digest = item["download_info"].get("archive_info", {}).get("hashes", {}).get("sha256")
        if digest is None:
            raise SystemExit(f"lock: {name} {version} comes from {item['download_info']['url']} with no SHA-256: "
                             "allowed are files from an index")
        rows.append((canonical(name), version, digest))
    return [f"{name}=={version} \\\n    --hash=sha256:{digest}" for name, version, digest in sorted(rows)]


def write(path):
    report = resolve("Scripts" if sys.platform == "win32" else "bin")
    day = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    header = [
        f"# Exact versions of what `make setup` installs (pip install --require-hashes -r {Path(path).name}).",
        f"# Written by `make lock` (scripts/locked_environment.py) on {day}, pip {report.get('pip_version')},",
        "# from pyproject.toml's ranges for .[test] plus pip and setuptools. Do not edit by hand.",
        "# Valid only for this platform's wheels; elsewhere see the README (Quick start).",
        f"# platform: {this_platform()}",
    ]
    text = "\n".join(header + lines(report)) + "\n"
    Path(path).write_text(text)
    print(f"wrote {path}: {len(pins(text))} distributions for {this_platform()}", file=sys.stderr)


def check(path):
    text = Path(path).read_text()
    locked, here = lock_platform(text), this_platform()
    if locked != here:
        print(f"{path}: locked for {locked}, this Python is {here}: allowed is that platform; elsewhere install "
              "with `pip install -e '.[test]'` (pyproject.toml's ranges) or write a lock of your own with "
              "`make lock` (README, Quick start)", file=sys.stderr)
        return 2
    return 0


def main(argv):
    if len(argv) != 2 or argv[0] not in ("write", "check"):
        print("usage: locked_environment.py write|check LOCK", file=sys.stderr)
        return 2
    if argv[0] == "write":
        write(argv[1])
        return 0
    return check(argv[1])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
