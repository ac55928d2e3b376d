"""The manual (the README and docs/) is written for users: no work-item words, no commit hashes, every
relative link and anchor resolving, every ``crisgeo ...`` command line parsing with the CLI's own parser."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from monitor.cli import build_parser
from monitor.cli.registry import UsageError

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

# what a manual for users does not say: how its work was organised
FORBIDDEN = {
    "an issue or item number": re.compile(r"\b(issues?|items?|tasks?)\s+#?\d+|#\d{2,}\b", re.I),
    "a session word": re.compile(r"\bsessions?\b|this session's", re.I),
    "a development run": re.compile(r"development runs?", re.I),
    # 7 to 40 hexadecimal characters with a digit and a letter: a commit
    "a commit hash": re.compile(r"\b(?=[0-9a-f]*\d)(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b"),
}


def _words(text: str) -> list[tuple[str, str]]:
    return [(what, m.group(0)) for what, rx in FORBIDDEN.items() for m in rx.finditer(text)]


def test_the_checks_see_what_they_look_for():
    assert [w for w, _ in _words("as issue 57 item 3 measured at 8cb6f37 this session")] == [
        "an issue or item number",
        "an issue or item number",
        "a session word",
        "a commit hash",
    ]
    assert _words("1.5 km, 6.912237115180778 urad, deadbee is a word, 2026-11-28") == []


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_the_page_speaks_to_users(page):
    assert _words(page.read_text()) == []


def _slug(heading: str) -> str:
    """GitHub's anchor of a Markdown heading."""
    text = re.sub(r"[`*_]|\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    return {_slug(m.group(1)) for m in re.finditer(r"^#+\s+(.*)$", page.read_text(), re.M)}


def _links(page: Path) -> list[str]:
    text = re.sub(r"^( {4}|\t).*$", "", page.read_text(), flags=re.M)  # code blocks hold no links
    return [m.group(1) for m in re.finditer(r"\]\(([^)\s]+)\)", text)]


def test_the_slug_is_githubs():
    assert _slug("Uncertainty (`jackknife.py`)") == "uncertainty-jackknifepy"
    assert _slug("Worst against total, and what the specification judges") == (
        "worst-against-total-and-what-the-specification-judges"
    )


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_relative_link_and_anchor_resolves(page):
    broken = []
    for link in _links(page):
        if re.match(r"[a-z]+:", link):  # http:, https:, mailto:
            continue
        path, _, anchor = link.partition("#")
        target = (page.parent / path).resolve() if path else page
        if not target.exists():
            broken.append(link)
        elif anchor and target.suffix == ".md" and anchor not in _anchors(target):
            broken.append(link)
    assert broken == []


# a placeholder's stand-in, by the option before it
VALUES = {
    "--date": "2026-01-01",
    "--since": "2026-01-01",
    "--until": "2026-01-02",
    "--satellite": "j01",
    "--listen": "127.0.0.1:9782",
    "--format": "netcdf",
    "--expires": "7d",
    "--rule": "spec",
    "--granules": "3",
    "--processes": "2",
    "--workers": "2",
    "--days": "3",
    "--seed": "1",
    "--clouds": "lapse:6.5",
    "--lon": "0",
}


def _command_lines(page: Path) -> list[str]:
    text = page.read_text()
    lines = re.findall(r"`(crisgeo [^`]+)`", text)
    lines += [m.group(1) for m in re.finditer(r"^(?: {4,}|\t)(crisgeo .*)$", text, re.M)]
    return lines


def _normalised(line: str) -> list[str]:
    """The words of a documented command line, its optional parts and placeholders made concrete."""
    line = re.split(r"\s{2,}", line.strip())[0]  # a description follows two spaces
    while re.search(r"\[[^\[\]]*\]", line):  # optional parts left out
        line = re.sub(r"\[[^\[\]]*\]", "", line)
    line = line.split(" | ")[0]  # alternatives: the first
    words = [w for w in shlex.split(line.replace("...", "")) if w]
    out = []
    for i, w in enumerate(words):
        if re.fullmatch(r"[A-Z][A-Z0-9_:.\-]*(\.[a-z]+)?|[A-Z]+\.[a-z]+|YYYY-MM-DD", w):
            w = VALUES.get(words[i - 1], "x") if i else w
        out.append(w)
    return out[1:]


def test_normalising_a_documented_line():
    assert _normalised("crisgeo run --config FILE [--satellite S] [--date YYYY-MM-DD]     the daily job") == [
        "run",
        "--config",
        "x",
    ]
    assert _normalised("crisgeo fingerprint | geolocate") == ["fingerprint"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_documented_command_parses(page):
    parser = build_parser()
    refused = []
    for line in _command_lines(page):
        words = _normalised(line)
        if len(words) < 2 or not re.fullmatch(r"[a-z][a-z-]*", words[0]):  # a command named, not a line
            continue
        try:
            parser.parse_args(words)
        except (UsageError, SystemExit) as exc:
            refused.append(f"{line}: {exc}")
    assert refused == []
