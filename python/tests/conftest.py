"""Shared fixtures: the repository's meshes and the command-line tool to compare against."""

import os
import shutil
from pathlib import Path

import pytest

import fairmesh

REPOSITORY = Path(__file__).resolve().parents[2]
BUNNY = REPOSITORY / "assets" / "bunny00.obj"


# Skips are allowed only where a thing cannot be had on the machine, and then loudly: with
# FAIRMESH_ALLOWED_SKIPS set (scripts/test_python.sh sets it), a skip whose reason contains none of
# its comma-separated phrases fails the run.
_skipped = []


def pytest_runtest_logreport(report):
    if report.skipped:
        longrepr = report.longrepr
        reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
        _skipped.append((report.nodeid, reason))


def pytest_sessionfinish(session, exitstatus):
    allowed = os.environ.get("FAIRMESH_ALLOWED_SKIPS")
    if allowed is None:
        return
    phrases = [phrase for phrase in allowed.split(",") if phrase]
    unexpected = [(test, reason) for test, reason in _skipped
                  if not any(phrase in reason for phrase in phrases)]
    if unexpected:
        for test, reason in unexpected:
            print(f"\nunexpected skip: {test}: {reason}")
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


@pytest.fixture(scope="session")
def bunny():
    return fairmesh.load(BUNNY)


@pytest.fixture(scope="session")
def cli():
    """The `fairmesh` binary: $FAIRMESH_CLI (scripts/test_python.sh sets it), else one built in
    the repository's target folder."""
    named = os.environ.get("FAIRMESH_CLI")
    if named:
        assert Path(named).is_file(), f"FAIRMESH_CLI={named} is not a file"
        return named
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPOSITORY / "target"))
    for profile in ("debug", "release"):
        candidate = target / profile / "fairmesh"
        if candidate.is_file():
            return str(candidate)
    found = shutil.which("fairmesh")
    if found:
        return found
    pytest.skip("no fairmesh binary: build it (cargo build) or set FAIRMESH_CLI")
