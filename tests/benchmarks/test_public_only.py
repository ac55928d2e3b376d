"""The benchmarks are part of the code: they call the product's public functions only (mypy and the import
contracts check the rest in .ci/run)."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _private_uses(source: str) -> list[str]:
    """Names starting with one underscore imported from, or read off, a module of the product."""
    tree = ast.parse(source)
    modules = {}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(("monitor", "alerts")):
            for a in node.names:
                if a.name.startswith("_"):
                    found.append(f"{node.module}.{a.name}")
                modules[a.asname or a.name] = node.module
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and node.attr.startswith("_")
            and not node.attr.startswith("__")
            and isinstance(node.value, ast.Name)
            and node.value.id in modules
        ):
            found.append(ast.unparse(node))
    return found


def test_the_check_sees_a_private_call():
    assert _private_uses("from monitor.assessment.assess import _x\n") == ["monitor.assessment.assess._x"]
    assert _private_uses("from monitor.simulate import case as sim\nsim._y()\n") == ["sim._y"]


def test_no_benchmark_calls_a_private_function_of_the_product():
    found = {p.name: _private_uses(p.read_text()) for p in sorted((ROOT / "benchmarks").glob("*.py"))}
    assert not {k: v for k, v in found.items() if v}
