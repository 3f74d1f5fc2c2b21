"""A drift variable's settings live in its module: its command-line options (``Options``,
read without importing the module) and where the fit gives its settings their values
(``derive`` from the options, ``first_pass`` from the training runs).

Generated from the registry where it can be: every module's declaration is compared with
what ``DriftSettings`` got from its text, so a new variable's option is covered without a
line here. The derivations are checked against their definitions computed independently
(numpy on the same window means, the documented defaults).
"""

from __future__ import annotations

import dataclasses
import importlib
import subprocess
import sys
import typing

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import InputError
from hrgtc.drift.variables import DRIFT_VARIABLES
from hrgtc.drift.variables.d2 import TAU2_FACTOR
from hrgtc.drift.variables.dpos import SWITCH_FRACTION
from hrgtc.settings.drift import (
    VARIABLE_OPTIONS,
    WARMUP_FACTOR,
    DriftSettings,
    declared_variables,
    variable_modules,
    variable_options,
)

from synthetic import THERMOMETER, lagged_run

MODULES = {importlib.import_module(f"hrgtc.drift.variables.{name}").VARIABLE.name:
           importlib.import_module(f"hrgtc.drift.variables.{name}")
           for name in variable_modules()}


def test_drift_settings_take_each_modules_declared_options():
    """Each variable module's ``Options``, imported, is what ``DriftSettings`` read from its
    text: the same fields, types, defaults and metadata (the panel filled), in grammar order,
    after ``--rate-tau-s``."""
    declared = []
    for v in DRIFT_VARIABLES:
        options = getattr(MODULES[v.name], "Options", None)
        if options is None:
            continue
        for name, kind in typing.get_type_hints(options).items():
            declared.append((name, kind, getattr(options, name)))
    assert [name for name, _, _ in declared] == list(VARIABLE_OPTIONS) == ["rate_tau2_s"]
    fields = {f.name: f for f in dataclasses.fields(DriftSettings)}
    hints = typing.get_type_hints(DriftSettings)
    order = list(fields)
    for name, kind, field in declared:
        assert hints[name] == kind, name
        assert fields[name].default == field.default, name
        assert {**field.metadata, "panel": "Drift model"} == dict(fields[name].metadata), name
    start = order.index("rate_tau_s") + 1
    assert order[start:start + len(declared)] == [name for name, _, _ in declared]


def test_the_text_declares_what_the_registry_holds():
    """Each module's name and order as read from its text are its ``VARIABLE``'s, and the
    ``--terms`` help lists the variables from them, in grammar order."""
    from hrgtc.settings import settings_of

    read = [(d.name, d.order) for d in declared_variables()]
    assert read == [(v.name, v.order) for v in DRIFT_VARIABLES]
    (terms,) = [s for s in settings_of(DriftSettings) if s.name == "terms"]
    listed = terms.help.split("Variables: ")[1].rstrip(".").replace(" (--aux)", "")
    assert listed.split(", ") == [v.name for v in DRIFT_VARIABLES]


def test_the_settings_read_no_variable_module():
    """``hrgtc.settings.drift`` reads the declarations as text: neither numpy nor a variable
    module is imported (so ``hrgtc --help`` stays quick)."""
    code = ("import sys, hrgtc.settings.drift as d; assert d.VARIABLE_OPTIONS; "
            "print(sorted(m for m in sys.modules if m == 'numpy' or "
            "m.startswith('hrgtc.drift')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


def _module(folder, name, options, order, before=""):
    (folder / f"{name}.py").write_text(
        f"import numpy as np\n\nfrom hrgtc.settings import setting\n{before}\n\n"
        f"class Options:\n{options}\n\nVARIABLE = make(name={name!r}, order={order})\n",
        encoding="utf-8")


def test_declarations_are_read_in_grammar_order_from_text(tmp_path):
    """Two modules (one importing numpy that is never run, one a constant it uses): their
    options in the order of their ``order=``, the panel the drift model's; the registry's
    other modules and those without ``Options`` give none."""
    _module(tmp_path, "zeta", '    zeta_s: float = setting(1.0, "Z.", unit="s")', 2)
    _module(tmp_path, "alpha", '    alpha_s: float | None = setting(\n        None, "A.", '
            'default_text=f"{FACTOR:g} × --rate-tau-s", panel="Mine")', 9,
            before="FACTOR = 3.0\nNOT_LITERAL = np.pi")
    (tmp_path / "spec.py").write_text("class Options:\n    x: int = 1\n", encoding="utf-8")
    (tmp_path / "plain.py").write_text("import numpy\n\nVARIABLE = make(name='plain', order=5)\n",
                                       encoding="utf-8")
    assert [(d.name, d.order) for d in declared_variables(tmp_path)] == [
        ("zeta", 2), ("plain", 5), ("alpha", 9)]
    found = variable_options(tmp_path)
    assert [(name, kind) for name, kind, _ in found] == [("zeta_s", float),
                                                         ("alpha_s", float | None)]
    assert found[0][2].metadata["panel"] == "Drift model" and found[0][2].default == 1.0
    assert found[1][2].metadata["default_text"] == "3 × --rate-tau-s"
    assert found[1][2].metadata["panel"] == "Mine"


def test_a_declaration_that_needs_the_module_is_refused(tmp_path):
    _module(tmp_path, "bad", '    bad_s: float = setting(float(np.pi), "B.")', 3)
    with pytest.raises(RuntimeError, match=r"bad\.py: its Options declaration uses 'np'"):
        variable_options(tmp_path)
    _module(tmp_path, "bad", '    bad_s: float = 3.0', 3)
    with pytest.raises(RuntimeError, match=r"bad\.py: Options\.bad_s is not a setting"):
        variable_options(tmp_path)
    (tmp_path / "bad.py").write_text("import numpy\n", encoding="utf-8")
    with pytest.raises(RuntimeError, match=r"bad\.py: .*VARIABLE = DriftVariable.*literal name"):
        variable_options(tmp_path)


def test_derivations_from_the_options():
    """d2: ``--rate-tau2-s``, else TAU2_FACTOR × ``--rate-tau-s``; a_NAME: the ``--aux``
    columns, a channel without one refused naming it."""
    d2, aux = MODULES["d2"].VARIABLE, MODULES["a_NAME"].VARIABLE
    given = {**DriftSettings().variable_options(), "rate_tau_s": 7.0, "aux_columns": {}}
    assert d2.derive(("d2",), given) == {"rate_tau2_s": TAU2_FACTOR * 7.0}
    assert d2.derive(("d2",), {**given, "rate_tau2_s": 45}) == {"rate_tau2_s": 45.0}
    mapped = {**given, "aux_columns": {"drive": "drive_v"}}
    assert aux.derive(("a_drive",), mapped) == {"aux_columns": {"drive": "drive_v"}}
    with pytest.raises(InputError, match=r"\['a_tilt'\] have no column.*--aux NAME=COLUMN"):
        aux.derive(("a_drive", "a_tilt"), mapped)


def test_derivations_from_the_first_pass():
    """dpos's switch: SWITCH_FRACTION × std of the df windows (1 when df is constant);
    a_NAME's centres: each channel's mean window."""
    rng = np.random.default_rng(3)
    df, drive = rng.normal(0.0, 2e-3, 200), rng.normal(4.0, 0.5, 200)
    dpos, aux = MODULES["dpos"].VARIABLE.first_pass, MODULES["a_NAME"].VARIABLE.first_pass
    assert dpos.reads(("dpos",)) == ("df",)
    got = dpos.derive(("dpos",), {"df": df})["switch_hz_per_s"]
    assert got == pytest.approx(SWITCH_FRACTION * np.sqrt(np.sum((df - df.mean()) ** 2) / 200))
    assert dpos.derive(("dpos",), {"df": np.full(5, 3e-3)}) == {"switch_hz_per_s": 1.0}
    assert aux.reads(("a_drive",)) == ("a_drive",)
    centre = aux.derive(("a_drive",), {"a_drive": drive})["aux_centres"]["drive"]
    assert centre == pytest.approx(float(np.sum(drive)) / drive.size)


def test_the_fit_gives_each_variable_its_derived_settings():
    """End to end: ``options={"rate_tau2_s": ...}`` reaches d2's filter and the warm-up
    (5 × the longest time constant); without d2 its setting keeps 0; an unknown option is
    refused naming the known ones."""
    runs = [lagged_run(seed=5), lagged_run(seed=6, start_c=-20.0, end_c=20.0)]
    terms = ("f", "df", "d2")
    with_d2 = drift.fit(runs, THERMOMETER, terms=terms, initial=terms, premove=0.999999,
                        options={"rate_tau2_s": 90.0})
    assert with_d2.settings.rate_tau2_s == 90.0
    assert with_d2.settings.warmup_s == WARMUP_FACTOR * 90.0
    without = drift.fit(runs, THERMOMETER, terms=("f", "df"), options={"rate_tau2_s": 90.0})
    assert without.settings.rate_tau2_s == 0.0
    assert without.settings.warmup_s == WARMUP_FACTOR * without.settings.rate_tau_s
    with pytest.raises(InputError, match=r"unknown drift variable option\(s\) \['tau3_s'\]; "
                                         r"the variables declare rate_tau2_s"):
        drift.fit(runs, THERMOMETER, terms=terms, options={"tau3_s": 1.0})
