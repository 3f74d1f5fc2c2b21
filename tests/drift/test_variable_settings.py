"""A drift variable's settings: its command-line options (declared with the other
variables' in ``hrgtc.settings.drift_variables``, which imports no numpy) and where the fit
gives its settings their values (``derive`` from the options, ``first_pass`` from the
training runs, in its module).

Generated from the declarations and the registry where it can be: every declared options
class is compared with what ``DriftSettings`` got, so a new variable's option is covered
without a line here. The derivations are checked against their definitions computed
independently (numpy on the same window means, the documented defaults).
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
from hrgtc.drift.variables.registry import check_declared, variable_modules
from hrgtc.settings import setting
from hrgtc.settings.drift import (
    VARIABLE_OPTIONS,
    WARMUP_FACTOR,
    DriftSettings,
    variable_options,
)
from hrgtc.settings.drift_variables import DECLARATIONS, Declaration

from synthetic import THERMOMETER, lagged_run

FOLDER = importlib.import_module("hrgtc.drift.variables").__path__[0]
MODULES = {importlib.import_module(f"hrgtc.drift.variables.{name}").VARIABLE.name:
           importlib.import_module(f"hrgtc.drift.variables.{name}")
           for name in variable_modules(FOLDER)}


def test_drift_settings_take_each_declared_option():
    """Each declared options class is in ``DriftSettings``: the same fields, types, defaults
    and metadata (the panel filled), in grammar order, after ``--rate-tau-s``."""
    declared = []
    for d in DECLARATIONS:
        for name, kind in typing.get_type_hints(d.options or object).items():
            declared.append((name, kind, getattr(d.options, name)))
    assert [name for name, _, _ in declared] == list(VARIABLE_OPTIONS) == [
        "rate_tau2_s", "gradient_saturation_c", "play_width_c"]
    fields = {f.name: f for f in dataclasses.fields(DriftSettings)}
    hints = typing.get_type_hints(DriftSettings)
    order = list(fields)
    for name, kind, field in declared:
        assert hints[name] == kind, name
        assert fields[name].default == field.default, name
        assert {**field.metadata, "panel": "Drift model"} == dict(fields[name].metadata), name
    start = order.index("rate_tau_s") + 1
    assert order[start:start + len(declared)] == [name for name, _, _ in declared]


def test_the_declarations_are_what_the_registry_holds():
    """The declared names are the modules' ``VARIABLE`` names in grammar order, and the
    ``--terms`` help lists them in that order."""
    from hrgtc.settings import settings_of

    assert [d.name for d in DECLARATIONS] == [v.name for v in DRIFT_VARIABLES]
    assert [v.order for v in DRIFT_VARIABLES] == sorted(v.order for v in DRIFT_VARIABLES)
    (terms,) = [s for s in settings_of(DriftSettings) if s.name == "terms"]
    listed = terms.help.split("Variables: ")[1].rstrip(".").replace(" (--aux)", "")
    assert listed.split(", ") == [v.name for v in DRIFT_VARIABLES]


def test_an_undeclared_or_misplaced_variable_is_refused():
    """The registry refuses a module without a declaration, a declaration without a module
    and the two in different orders, naming the file to edit."""
    found = DRIFT_VARIABLES
    check_declared(found)
    new = dataclasses.replace(found[0], name="d3", order=99)
    with pytest.raises(RuntimeError, match=r"settings/drift_variables\.py: not declared: "
                                           r"\['d3'\]; add a Declaration\(name, options\)"):
        check_declared((*found, new))
    with pytest.raises(RuntimeError, match=r"declared without a module: \['a_NAME'\]"):
        check_declared(found[:-1])
    with pytest.raises(RuntimeError, match="the order differs"):
        check_declared(found[::-1])


def test_the_settings_import_no_variable_module():
    """``hrgtc.settings.drift`` imports the declarations: neither numpy nor a variable
    module is imported (so ``hrgtc --help`` stays quick)."""
    code = ("import sys, hrgtc.settings.drift as d; assert d.VARIABLE_OPTIONS; "
            "print(sorted(m for m in sys.modules if m == 'numpy' or "
            "m.startswith('hrgtc.drift')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"


def test_declared_options_in_grammar_order():
    """Two declarations' options, in the declarations' order, the panel the drift model's
    unless one is named; a declaration without options gives none."""

    class Zeta:
        zeta_s: float = setting(1.0, "Z.", unit="s")

    class Alpha:
        alpha_s: float | None = setting(None, "A.", default_text="3 × --rate-tau-s",
                                        panel="Mine")

    found = variable_options((Declaration("zeta", Zeta), Declaration("plain"),
                              Declaration("alpha", Alpha)))
    assert [(name, kind) for name, kind, _ in found] == [("zeta_s", float),
                                                         ("alpha_s", float | None)]
    assert found[0][2].metadata["panel"] == "Drift model" and found[0][2].default == 1.0
    assert found[1][2].metadata["default_text"] == "3 × --rate-tau-s"
    assert found[1][2].metadata["panel"] == "Mine"


def test_an_option_that_is_not_a_setting_is_refused():
    class Bad:
        bad_s: float = 3.0

    with pytest.raises(RuntimeError, match=r"Bad\.bad_s \(drift variable bad\) is not a "
                                           r"setting"):
        variable_options((Declaration("bad", Bad),))


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
