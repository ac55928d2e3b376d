"""The notebook examples of docs/results.md, run as a scientist would paste them, on a store of one day
(the first morning) and of several."""

import datetime as dt
import re

import matplotlib
import pytest

from monitor.service.store.sqlite import Store
from monitor.simulate.history import fill_store
from tests.invoke import ROOT

matplotlib.use("Agg")
pytest.importorskip("xarray")


def _snippets() -> list[str]:
    """The indented code blocks of docs/results.md that read a store."""
    text = (ROOT / "docs" / "results.md").read_text()
    blocks = re.findall(r"((?:^    .*\n)+)", text, re.M)
    return ["\n".join(line[4:] for line in b.splitlines()) for b in blocks if "open_store(" in b]


@pytest.mark.parametrize("days", [1, 3])
def test_the_notebook_examples_run_on_a_store_of_any_length(tmp_path, days):
    import matplotlib.pyplot as plt

    db = tmp_path / "crisgeo.sqlite"
    with Store(db) as store:
        fill_store(store, ["j01"], dt.date(2026, 11, 22), days, step_day=None, seed=3)
    snippets = _snippets()
    assert snippets, "docs/results.md lost its notebook examples"
    for code in snippets:
        exec(compile(code.replace("demo-state/crisgeo.sqlite", str(db)), "docs/results.md", "exec"), {})
        assert plt.get_fignums(), code  # each example drew something
        plt.close("all")


def test_the_documented_silence_is_in_the_future_and_parses():
    """docs/operations.md's silence example, parsed by the command line: it ends after now."""
    import shlex

    from monitor.cli import build_parser

    text = (ROOT / "docs" / "operations.md").read_text()
    examples = re.findall(r"`(crisgeo alerts silence [^`]+)`", text)
    assert examples
    for example in examples:  # the alerts section's and the runbooks'
        args = build_parser().parse_args(shlex.split(" ".join(example.split()))[1:])
        assert args.expires > dt.datetime.now(dt.timezone.utc) + dt.timedelta(days=6)


def test_the_docs_link_only_to_files_that_exist():
    """Every relative link and image of README.md, docs/*.md and the studies' reports and records resolves
    from the file's own folder."""
    pages = [
        ROOT / "README.md",
        *sorted((ROOT / "docs").glob("*.md")),
        *sorted((ROOT / "studies").rglob("*.md")),
    ]
    for page in pages:
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text()):
            if "://" not in target and not target.startswith("mailto:"):
                assert (page.parent / target).exists(), f"{page.name}: {target}"


def test_the_readme_shows_the_table_the_demo_prints():
    """The README's sample of the demo's output has the FOR table's header and units lines as printed."""
    from monitor.core.tables import for_table

    readme = [line[4:].rstrip() for line in (ROOT / "README.md").read_text().splitlines()]
    header, units = for_table([])[:2]
    i = readme.index(header.rstrip())
    assert readme[i + 1] == units.rstrip()


def test_sizing_is_stated_once_and_linked():
    """The cost of a satellite-day and of the demo is in docs/performance.md's "Sizing"; the README and the
    operations guide link to it instead of stating figures of their own."""
    perf = (ROOT / "docs" / "performance.md").read_text()
    assert "\n## Sizing\n" in perf
    for page in (ROOT / "README.md", ROOT / "docs" / "operations.md"):
        text = page.read_text()
        assert "performance.md#sizing" in text, page.name
        stated = ("98.7 s", "175 CPU-s", "1.82 GB", "1.7 GB", "80 kB", "2.5 min", "25-30 s", "1.9 GB")
        assert not [x for x in stated if x in text], page.name  # the Sizing table's figures, or old ones
