"""The manual (the README and docs/) is written for users: no work-item words, no commit hashes, every
relative link and anchor resolving, every ``crisgeo ...`` command line parsing with the CLI's own parser."""

from __future__ import annotations

import argparse
import re
import shlex
from pathlib import Path

import pytest

from monitor.cli import build_parser
from monitor.cli.registry import UsageError

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# where else a user meets a command line: the shipped configurations' comments and the unit
SHIPPED = [*sorted((ROOT / "configs").rglob("*.yaml")), *sorted((ROOT / "systemd").glob("*"))]

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
    if page.suffix != ".md":  # a configuration's comment or a unit's Exec line: the rest of its line
        text = re.sub(r"\\\n#?\s*", " ", text)  # a line continued in the next (comment) line
        return [m.group(1).rstrip() for m in re.finditer(r"(?:^|[\s/=])(crisgeo [a-z][^\n#`]*)", text)]
    lines = [re.sub(r"\s*\n\s*", " ", m) for m in re.findall(r"`(crisgeo [^`]+)`", text)]  # wrapped
    # a code block's command, with the lines indented under it that continue it
    lines += [
        " ".join(part.strip() for part in m.group(1).splitlines())
        for m in re.finditer(r"^ {4}(crisgeo .*(?:\n {6,}\S.*)*)$", text, re.M)
    ]
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


def _subparser(parser, name: str):
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices.get(name)


def _options_named(line: str) -> list[tuple[str, list[str]]]:
    """Every option a documented line names, optional parts included, with the literal values written after
    it (each alternative of ``a|b``; placeholders in capitals are not literal)."""
    line = re.split(r"\s{2,}", line.strip())[0]
    words = re.findall(r"--?[A-Za-z][\w-]*|[^\s\[\]|]+(?:\|[^\s\[\]|]+)*", line.replace("...", ""))
    out = []
    for i, w in enumerate(words):
        if not w.startswith("-"):
            continue
        name, _, inline = w.partition("=")
        nxt = inline or (words[i + 1] if i + 1 < len(words) else "")
        literal = [] if nxt.startswith("-") or re.search(r"[A-Z]", nxt) else nxt.split("|")
        out.append((name, [v for v in literal if v]))
    return out


def _problems_of(parser, line: str) -> list[str]:
    words = _normalised(line)
    if len(words) < 2 or not re.fullmatch(r"[a-z][a-z-]*", words[0]):
        return []
    sub = _subparser(parser, words[0])
    if sub is None:
        return [f"{line}: no command {words[0]!r}"]
    out = []
    for name, values in _options_named(line):
        action = sub._option_string_actions.get(name) or parser._option_string_actions.get(name)
        if action is None:
            out.append(f"{line}: {words[0]} has no option {name}")
        elif action.help == argparse.SUPPRESS and name not in ("-v", "--verbose", "--log-format"):
            out.append(f"{line}: {name} is a deprecated spelling")
        elif action.choices is not None and values:
            out += [
                f"{line}: {name} {v!r} is not one of {list(action.choices)}"
                for v in values
                if v not in action.choices
            ]
    return out


def test_the_option_check_sees_what_it_looks_for():
    parser = build_parser()
    assert _problems_of(parser, "crisgeo assess PATH... [--json OUT.json]")
    assert _problems_of(parser, "crisgeo assess PATH... [--kernel top-hat|response]")
    assert _problems_of(parser, "crisgeo reprocess --config F --since D --until D [--workers 8]")
    assert _problems_of(parser, "crisgeo alerts silence --config F --until 7d")
    assert _problems_of(parser, "crisgeo assess PATH... [--out R.json] [--kernel top-hat|footprint]") == []


@pytest.mark.parametrize("page", PAGES + SHIPPED, ids=lambda p: p.name)
def test_every_option_the_manual_names_exists_with_its_values(page):
    parser = build_parser()
    assert [p for line in _command_lines(page) for p in _problems_of(parser, line)] == []


def _config_keys() -> set[str]:
    from monitor.config.reference import reference

    return set(re.findall(r"^\| `([a-z_.]+)`", reference(), re.M))


def _keys_named(text: str) -> list[str]:
    """The configuration keys a page names: ``section.key`` in backticks, and a bare ``key`` in backticks in
    the same table cell or sentence as a ``section.key`` (``assessment.half_steps``, ``step_urad``)."""
    sections = {k.split(".")[0] for k in _config_keys() if "." in k}
    out = []
    for row in re.findall(r"^\|.*\|$", text, re.M):  # a table's row: its first cell names keys
        cell = row.split("|")[1]
        dotted = [k for k in re.findall(r"`([a-z_]+(?:\.[a-z_0-9]+)+)`", cell) if k.split(".")[0] in sections]
        if len(dotted) == 1:
            section = dotted[0].split(".")[0]
            out += [f"{section}.{k}" for k in re.findall(r"`([a-z]+_[a-z_]+)`", cell)]
    named = re.findall(r"`([a-z_]+(?:\.[a-z_0-9]+)+)`", text)
    out += [k for k in named if k.split(".")[0] in sections and k.rsplit(".", 1)[-1] not in _code_names()]
    return out


def _code_names() -> set[str]:
    """The names the code defines (functions, modules): ``store.save_day`` names code, not a key."""
    names = set()
    for path in [*(ROOT / "monitor").rglob("*.py"), *(ROOT / "alerts").rglob("*.py")]:
        names.add(path.stem)
        names |= set(re.findall(r"^\s*def ([a-z_]\w*)", path.read_text(), re.M))
    return names


def test_the_key_check_sees_what_it_looks_for():
    keys = _config_keys()
    assert "assessment.step_urad" in keys
    assert [k for k in _keys_named("| `assessment.half_steps`, `step_m` | 10 |") if k not in keys] == [
        "assessment.step_m"
    ]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_configuration_key_the_manual_names_exists(page):
    keys = _config_keys()
    # a key's parent is a key too (alerts.email), and a mapping's entries are named by its parent
    known = keys | {k.rsplit(".", 1)[0] for k in keys}
    unknown = [
        k
        for k in _keys_named(page.read_text())
        if k not in known and k.rsplit(".", 1)[0] not in {"source.buckets", "source.calibration"}
    ]
    assert unknown == []
