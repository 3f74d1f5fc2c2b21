"""The docs' generated tables: the option tables and the registries' tables.

A docs page holds ``<!-- options: KEY -->`` and ``<!-- /options -->`` around a table of
the options generated from a settings class (:data:`DOCUMENTED`), and
``<!-- table: KEY -->`` and ``<!-- /table -->`` around a table a registry writes
(:data:`TABLES`: the drift variables and their backends); regenerate them with::

    PYTHONPATH=src python -m hrgtc.cli.options_tables docs/guide/*.md docs/real-loggers/*.md \
        docs/reliability.md

``tests/cli/test_params.py`` fails while a page's option table differs from its class,
``tests/drift/test_variables.py`` while the variables' table differs from the registry.
"""

from __future__ import annotations

from collections.abc import Sequence

from hrgtc.cli.params import option_settings

#: The settings classes whose options each command generates, by the docs page that lists them.
DOCUMENTED = {
    "calibrate": ("hrgtc.settings.calibration", "CalibrationSettings"),
    "calibrate_inputs": ("hrgtc.settings.inputs", "CalibrationInputs"),
    "temperature_reference": ("hrgtc.settings.inputs", "TemperatureReferenceSettings"),
    "holdout": ("hrgtc.settings.inputs", "HoldoutSettings"),
    "reading": ("hrgtc.settings.reading", "ReadSettings"),
    "compensate": ("hrgtc.settings.compensation", "CompensateSettings"),
    "evaluate": ("hrgtc.settings.compensation", "EvaluationSettings"),
    "report": ("hrgtc.settings.compensation", "ReportSettings"),
    "export": ("hrgtc.settings.export", "ExportSettings"),
    "fleet_simulate": ("hrgtc.settings.fleet", "FleetSimulation"),
    "fleet_calibrate": ("hrgtc.settings.fleet", "FleetCalibration"),
    "fleet_evaluate": ("hrgtc.settings.fleet", "FleetEvaluation"),
    "fleet_cluster": ("hrgtc.settings.fleet", "FleetCluster"),
    "demo": ("hrgtc.settings.fleet", "DemoSettings"),
    "simulate": ("hrgtc.settings.simulation", "SimulationSettings"),
    "simulate_logger": ("hrgtc.settings.simulation", "LoggerSettings"),
    "update": ("hrgtc.settings.update", "UpdateSettings"),
}

#: The tables a registry writes, by key: (module, function returning the Markdown).
TABLES = {
    "drift_variables": ("hrgtc.drift.variables", "docs_table"),
}


def options_table(cls: type) -> str:
    """A Markdown table of the options generated from ``cls``: option, default, meaning."""
    rows = ["| option | default | meaning |", "|---|---|---|"]
    for s in option_settings(cls):
        text = s.full_help().replace("|", "\\|").replace("<", "&lt;")
        if s.range_text() is not None:
            text += f" Range: {s.range_text()}."
        rows.append(f"| `{s.option}` | {s.shown_default().replace('|', chr(92) + '|')} "
                    f"| {text} |")
    return "\n".join(rows)


def settings_class(key: str) -> type:
    """The settings class of a docs table (a key of :data:`DOCUMENTED`)."""
    import importlib

    module, name = DOCUMENTED[key]
    return getattr(importlib.import_module(module), name)  # type: ignore[no-any-return]


def registry_table(key: str) -> str:
    """The Markdown of a registry's table (a key of :data:`TABLES`)."""
    import importlib

    module, name = TABLES[key]
    return str(getattr(importlib.import_module(module), name)())


def update_docs(text: str) -> str:
    """``text`` with every ``<!-- options: KEY -->`` ... ``<!-- /options -->`` table
    regenerated from its settings class, and every ``<!-- table: KEY -->`` ...
    ``<!-- /table -->`` from its registry."""
    import re

    def options(match: re.Match[str]) -> str:
        body = options_table(settings_class(match.group(2)))
        return f"{match.group(1)}\n{body}\n{match.group(4)}"

    def table(match: re.Match[str]) -> str:
        return f"{match.group(1)}\n{registry_table(match.group(2))}\n{match.group(4)}"

    # lazy: an empty block ends at its own closing marker, not at a later table's
    text = re.sub(r"(<!-- options: (\w+) -->)\n(.*?)(<!-- /options -->)", options, text,
                  flags=re.S)
    return re.sub(r"(<!-- table: (\w+) -->)\n(.*?)(<!-- /table -->)", table, text,
                  flags=re.S)


def main(paths: Sequence[str]) -> int:
    """Regenerate the option tables of the docs pages ``paths`` in place."""
    from pathlib import Path

    for path in paths:
        page = Path(path)
        text = page.read_text(encoding="utf-8")
        new = update_docs(text)
        if new != text:
            page.write_text(new, encoding="utf-8")
            print(f"updated {page}")  # a developer's tool, run by hand
    return 0


if __name__ == "__main__":
    import sys

    raise SystemExit(main(sys.argv[1:]))
