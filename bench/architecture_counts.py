"""The counts of issue 28 ("Architecture, round two"), read off the source, as one JSON line.

    python bench/architecture_counts.py

* ``long_functions``: functions (and methods) longer than 80 lines, docstring included;
* ``many_parameters``: functions with 10 parameters or more (``self``/``cls`` not counted,
  ``*args``/``**kwargs`` counted as one each);
* ``model_kind_branches``: ``isinstance`` tests on a model type (``Model``, ``AxisModel``;
  before issue 28 item 1 ``UnitModel``, ``InstrumentModel``) and ``is_single_axis`` reads
  outside ``model.py``;
* ``summary_return_types``: the return annotations of every ``summary()``, counted;
* ``partial_fit_without_finish``: classes with a ``partial_fit`` and no ``finish``;
* ``record_classes``: ``msgspec`` record classes (subclasses of ``Record``).

``tests/test_architecture_counts.py`` holds each count at or below the figure in
docs/architecture.md, so the house cannot slide back unnoticed.
"""

from __future__ import annotations

import ast
import collections
import json
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[1] / "src" / "hrgtc"
LONG = 80
MANY = 10
#: The model types a branch on the model's kind tests for (``model_kind_branches``).
_MODEL_TYPES = {"Model", "AxisModel", "UnitModel", "InstrumentModel"}


def _parameters(node: ast.FunctionDef | ast.AsyncFunctionDef) -> int:
    args = node.args
    names = [a.arg for a in (*args.posonlyargs, *args.args, *args.kwonlyargs)]
    if names and names[0] in ("self", "cls"):
        names = names[1:]
    return len(names) + (args.vararg is not None) + (args.kwarg is not None)


def counts(source: Path = SOURCE) -> dict[str, object]:
    """Every count of the module docstring, with the names behind the first two."""
    long: list[str] = []
    many: list[str] = []
    branches = 0
    summaries: collections.Counter[str] = collections.Counter()
    unfinished: list[str] = []
    records = 0
    for path in sorted(source.rglob("*.py")):
        relative = path.relative_to(source.parent).as_posix()
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                where = f"{relative}:{node.lineno} {node.name}"
                if node.end_lineno - node.lineno + 1 > LONG:
                    long.append(where)
                if _parameters(node) >= MANY:
                    many.append(where)
                if node.name == "summary":
                    summaries[ast.unparse(node.returns) if node.returns else "None"] += 1
            elif isinstance(node, ast.ClassDef):
                methods = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
                if "partial_fit" in methods and "finish" not in methods:
                    unfinished.append(f"{relative}:{node.lineno} {node.name}")
                if any(ast.unparse(b).endswith("Record") for b in node.bases):
                    records += 1
            elif isinstance(node, ast.Call) and relative != "hrgtc/model.py":
                if (isinstance(node.func, ast.Name) and node.func.id == "isinstance"
                        and len(node.args) == 2
                        and _MODEL_TYPES & {n.id for n in ast.walk(node.args[1])
                                            if isinstance(n, ast.Name)}):
                    branches += 1
            elif (isinstance(node, ast.Attribute) and node.attr == "is_single_axis"
                  and relative != "hrgtc/model.py"):
                branches += 1
    return {"name": "architecture_counts", "long_functions": len(long),
            "many_parameters": len(many), "model_kind_branches": branches,
            "summary_return_types": dict(sorted(summaries.items())),
            "partial_fit_without_finish": len(unfinished), "record_classes": records,
            "long_function_names": long, "many_parameter_names": many}


def main() -> int:
    figures = counts()
    print(json.dumps({k: v for k, v in figures.items() if not k.endswith("_names")}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
