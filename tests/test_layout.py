"""The package layout stays true: imports flow one way, no module imports in a circle.

Every module of ``src/hrgtc`` is parsed (ast, nothing is imported), each import
is resolved to the module it loads, and two rules are checked:

1. **One way**: a module imports only from its own stage or from a lower one,
   in the order of README's "Architecture" section (:data:`STAGES`).
2. **No circle**: the graph of module-level imports has no cycle (a package's
   ``__init__`` counts as a module, so a submodule that imports its own package
   is a circle).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "hrgtc"

#: The stages, lowest first; a module may import its own stage and the ones above it in
#: this list. Stages on one line do not import each other.
STAGES: list[set[str]] = [
    {"hrgtc._meta", "hrgtc.errors", "hrgtc._process"},
    {"hrgtc.files", "hrgtc.progress"},
    {"hrgtc.recording"},
    {"hrgtc.thermometry"},
    {"hrgtc.drift"},
    {"hrgtc.model_schema"},
    {"hrgtc.model", "hrgtc.paper"},
    {"hrgtc.compensate", "hrgtc.simulate"},
    {"hrgtc.evaluation"},
    {"hrgtc.report"},
    {"hrgtc.calibration"},
    {"hrgtc.instrument"},
    {"hrgtc.fleet"},
    {"hrgtc.demo"},
    {"hrgtc.cli", "hrgtc"},
]


def module_name(path: Path) -> str:
    parts = ("hrgtc", *path.relative_to(SOURCE).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(SOURCE.rglob("*.py"))}


def stage_of(module: str) -> str:
    """The stage a module belongs to: ``hrgtc.<first part>`` (the package itself for __init__)."""
    parts = module.split(".")
    return ".".join(parts[:2])


def rank(module: str) -> int:
    stage = stage_of(module)
    for level, stages in enumerate(STAGES):
        if stage in stages:
            return level
    raise AssertionError(f"{module}: stage {stage} is not in STAGES; add it where it belongs")


def imports(module: str, top_level_only: bool) -> set[str]:
    """Modules that ``module`` imports (``from pkg import sub`` resolves to ``pkg.sub``)."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    found: set[str] = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == "hrgtc")
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            if base.split(".")[0] != "hrgtc":
                continue
            for alias in node.names:
                candidate = f"{base}.{alias.name}"
                found.add(candidate if candidate in MODULES else base)
    return found


def test_every_module_belongs_to_a_stage():
    for module in MODULES:
        rank(module)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_flow_one_way(module):
    upward = []
    for target in sorted(imports(module, top_level_only=False)):
        assert target in MODULES, f"{module} imports {target}, which does not exist"
        same_stage = stage_of(target) == stage_of(module)
        if not same_stage and rank(target) >= rank(module):
            upward.append(target)
    assert not upward, f"{module} imports from a stage that is not below it: {upward}"


def test_no_import_cycles():
    graph = {m: imports(m, top_level_only=True) for m in MODULES}
    # an import of pkg.sub first runs pkg/__init__: the edge to the package is implied
    for module in MODULES:
        for target in list(graph[module]):
            parent = target.rpartition(".")[0]
            while parent and parent != "hrgtc":
                if parent in MODULES and not module.startswith(parent + ".") and module != parent:
                    graph[module].add(parent)
                parent = parent.rpartition(".")[0]
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for target in sorted(graph.get(node, ())):
            if target == node:
                continue
            if state.get(target) == 1:
                cycle = [*stack[stack.index(target):], target]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if target not in state:
                visit(target)
        stack.pop()
        state[node] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module)


def test_version_module_imports_nothing_of_hrgtc():
    assert imports("hrgtc._meta", top_level_only=False) == set()
    assert imports("hrgtc", top_level_only=True) == {"hrgtc._meta"}


def test_the_rules_catch_a_circle_and_an_upward_import(tmp_path, monkeypatch):
    """The checker itself can fail: a fake upward import and a fake cycle are found."""
    fake = dict(MODULES)
    low = tmp_path / "low.py"
    low.write_text("from hrgtc.report import build_report\n")
    a = tmp_path / "a.py"
    a.write_text("import hrgtc.drift.b\n")
    b = tmp_path / "b.py"
    b.write_text("from hrgtc.drift import a\n")
    fake.update({"hrgtc.recording.low": low, "hrgtc.drift.a": a, "hrgtc.drift.b": b})
    monkeypatch.setitem(globals(), "MODULES", fake)
    with pytest.raises(AssertionError, match="not below it"):
        test_imports_flow_one_way("hrgtc.recording.low")
    with pytest.raises(AssertionError, match="import cycle"):
        test_no_import_cycles()
