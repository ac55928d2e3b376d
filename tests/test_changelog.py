"""The CHANGELOG as Keep a Changelog 1.1.0 lays it out: an Unreleased section, then released versions with
their dates, newest first, the newest being the package's version; sections of the six kinds only; and it
speaks to users, not of the work items that made the changes."""

import datetime as dt
import re
import tomllib

from tests.invoke import ROOT

KINDS = {"Added", "Changed", "Deprecated", "Removed", "Fixed", "Security"}


def test_the_changelog_keeps_a_changelog_and_its_newest_release_is_the_packages_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    heads = re.findall(r"^## (.+)$", text, re.MULTILINE)
    assert heads[0] == "[Unreleased]"
    releases = [re.fullmatch(r"\[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})", h) for h in heads[1:]]
    assert releases and all(releases), heads
    versions = [tuple(map(int, m[1].split("."))) for m in releases]
    dates = [dt.date.fromisoformat(m[2]) for m in releases]
    assert versions == sorted(versions, reverse=True) and dates == sorted(dates, reverse=True)
    package = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert releases[0][1] == package
    assert set(re.findall(r"^### (.+)$", text, re.MULTILINE)) <= KINDS
    assert not re.search(r"\b(issue|item) \d+|\b[0-9a-f]{7}\b", text)  # no work items, no commit hashes
