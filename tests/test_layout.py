"""The code's layout as docs/layout.md draws it: module sizes, unique names, the rooms against the tree."""

import re
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAYOUT = (ROOT / "docs" / "layout.md").read_text()
MODULES = sorted(p for pkg in ("monitor", "alerts") for p in (ROOT / pkg).rglob("*.py"))


def test_no_module_outside_the_simulator_passes_600_lines():
    long = {
        str(p.relative_to(ROOT)): n
        for p in MODULES
        if "simulate" not in p.parts and (n := len(p.read_text().splitlines())) > 600
    }
    assert long == {}


def test_no_two_modules_share_a_file_name():
    names = Counter(p.name for p in MODULES if p.name not in ("__init__.py", "__main__.py"))
    assert {n: c for n, c in names.items() if c > 1} == {}


def test_every_package_and_top_level_folder_is_on_the_page():
    packages = {f"monitor/{p.name}/" for p in (ROOT / "monitor").iterdir() if (p / "__init__.py").exists()}
    folders = {f"{d}/" for d in ("alerts", "configs", "docs", "systemd", "tests", "benchmarks", "studies")}
    assert {p for p in packages | folders if p not in LAYOUT} == set()


def test_every_module_the_page_names_exists():
    named = set(re.findall(r"\b([a-z_]+\.py)\b", LAYOUT))
    have = {p.name for p in MODULES} | {p.name for p in (ROOT / "tests").rglob("*.py")}
    have |= {p.name for p in (ROOT / "benchmarks").glob("*.py")} | {
        p.name for p in (ROOT / "studies").glob("*.py")
    }
    assert named - have == set()


def test_no_test_writes_sql_outside_the_stores_own_tests():
    """SQL lives in monitor/service/store/ and its tests; every other test goes through the store's API."""
    import re

    sql = re.compile(
        r"\.db\.execute|\bsqlite3\.connect|\bPRAGMA "
    )  # InfluxQL and PromQL are the servers' own
    tests = ROOT / "tests"
    found = [
        f"{p.relative_to(ROOT)}:{i}"
        for p in tests.rglob("*.py")
        if not p.is_relative_to(tests / "service" / "store") and p.name != "test_layout.py"
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if sql.search(line)
    ]
    assert found == []
