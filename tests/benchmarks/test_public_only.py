"""The harnesses and the studies stand on the product: they call its public functions only, and they never
assign into it (what a study varies, it passes through the seam for studies, monitor.assessment.seam). A
study uses another study's public names only. mypy and the import contracts check the rest in .ci/run."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _private_uses(source: str) -> list[str]:
    """Names starting with one underscore imported from, or read off, a module of the product or a study."""
    tree = ast.parse(source)
    modules = {}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
            ("monitor", "alerts", "studies")
        ):
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


def _product_assignments(source: str) -> list[str]:
    """Assignments (``=``, augmented, ``setattr``) to an attribute of a product module or of a name
    imported from one."""
    tree = ast.parse(source)
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(("monitor", "alerts")):
            names |= {a.asname or a.name for a in node.names}
        elif isinstance(node, ast.Import):
            product = [a for a in node.names if a.name.startswith(("monitor", "alerts"))]
            names |= {a.asname or a.name.split(".")[0] for a in product}

    def root(node):
        while isinstance(node, ast.Attribute):
            node = node.value
        return node.id if isinstance(node, ast.Name) else None

    found = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Assign):
            targets = node.targets
        elif isinstance(node, (ast.AugAssign, ast.AnnAssign)):
            targets = [node.target]
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "setattr":
            targets = [ast.Attribute(value=node.args[0], attr="?")] if node.args else []
        for t in targets:
            for leaf in t.elts if isinstance(t, ast.Tuple) else [t]:
                if isinstance(leaf, ast.Attribute) and root(leaf) in names:
                    found.append(ast.unparse(leaf))
    return found


def _scripts():
    return sorted((ROOT / "benchmarks").glob("*.py")) + sorted((ROOT / "studies").glob("*.py"))


def test_the_check_sees_an_assignment_into_the_product():
    assert _product_assignments("from monitor.collocation import render\nrender.rendered_bt = f\n") == [
        "render.rendered_bt"
    ]
    assert _product_assignments("from monitor.simulate.case import Simulator\nSimulator.met = f\n") == [
        "Simulator.met"
    ]
    assert _product_assignments("import monitor.estimation\nsetattr(monitor, 'x', 1)\n") == ["monitor.?"]
    assert _product_assignments("from monitor.config import x\ny = x\ny.z = 1\n") == []


def test_no_harness_or_study_assigns_into_the_product():
    found = {p.name: _product_assignments(p.read_text()) for p in _scripts()}
    assert not {k: v for k, v in found.items() if v}


def test_the_check_sees_a_private_call():
    assert _private_uses("from monitor.assessment.assess import _x\n") == ["monitor.assessment.assess._x"]
    assert _private_uses("from monitor.simulate import case as sim\nsim._y()\n") == ["sim._y"]
    assert _private_uses("from studies.lift_decision import _s\n") == ["studies.lift_decision._s"]


def test_no_harness_or_study_calls_a_private_function_of_the_product_or_of_a_study():
    found = {p.name: _private_uses(p.read_text()) for p in _scripts()}
    assert not {k: v for k, v in found.items() if v}
