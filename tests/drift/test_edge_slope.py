"""The slope a single run's model carries beyond its trained temperatures (drift.edge_slope)."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.drift.cross_validation import Windowed
from hrgtc.drift.edge_slope import EDGE_SLOPE_Z, edge_slopes, unknown_edge_slope
from hrgtc.drift.features import hierarchy, parse_terms
from hrgtc.drift.regression import newey_west_inflation

NAMES = ("f", "f^2", "f^3", "df")
SCALES = {"f": 4.0, "df": 0.01}


def _windows(slope: float, curve: float, noise: float, seed: int = 3):
    """40 windows of one cooling run, f from 4 down to -4 Hz, bias = slope f + curve f²
    + white noise; the design as the fit builds it (terms of value / scale)."""
    rng = np.random.default_rng(seed)
    f = np.linspace(4.0, -4.0, 40)
    df = np.full(f.size, -0.01) + 1e-4 * np.sin(f)
    bias = slope * f + curve * f ** 2 + noise * rng.standard_normal(f.size)
    values = {"f": f / SCALES["f"], "df": df / SCALES["df"]}
    x = np.column_stack([t.evaluate(values) for t in parse_terms(NAMES)])
    return Windowed(x, bias, np.zeros(f.size, dtype=np.int64), NAMES, rate=df,
                    time_s=np.arange(f.size) * 60.0, temperature=f,
                    variables={"f": f, "df": df}, scales=SCALES)


def test_edge_slopes_are_the_derivative_of_numpy_s_polynomial_with_its_error():
    data = _windows(5.0, 0.7, 0.3)
    found = edge_slopes(data, ["f", "f^2", "f^3"])
    # numpy alone: the cubic in f (Hz), its derivative at -4 and 4 Hz, its covariance
    f, bias = data.temperature, data.bias_dph
    coefficients, unscaled = np.polyfit(f, bias, 3, cov="unscaled")
    residual = bias - np.polyval(coefficients, f)
    inflation, _ = newey_west_inflation(residual)
    covariance = inflation * residual @ residual / (f.size - 4) * unscaled
    for (slope, error), edge in zip(found, (-4.0, 4.0), strict=True):
        gradient = np.array([3 * edge ** 2, 2 * edge, 1.0, 0.0])  # d/df of f³, f², f, 1
        assert slope == pytest.approx(gradient @ coefficients, rel=1e-9)
        assert error == pytest.approx(np.sqrt(gradient @ covariance @ gradient), rel=1e-9)
    assert found[0][0] == pytest.approx(5.0 - 2 * 0.7 * 4.0, abs=3 * found[0][1])


def test_a_bend_that_leaves_the_edge_slope_unknown_goes_and_the_line_stays():
    data = _windows(2.0, 0.0, 2.0)
    kept = ("f", "f^2", "f^3", "df")
    parents = hierarchy(parse_terms(NAMES))
    terms, record = unknown_edge_slope(data, kept, parents=parents)
    line, error = record["line"]
    assert abs(line) >= EDGE_SLOPE_Z * error  # the line's sign is known
    assert any(abs(s) < EDGE_SLOPE_Z * e for s, e in (record["cold"], record["hot"]))
    assert terms == ("f", "df") and record["dropped"] == ["f^2", "f^3"]
    # the user's starting term stays, and its parent with it
    terms, record = unknown_edge_slope(data, kept, parents=parents, keep=["f^2"])
    assert terms == ("f", "f^2", "df") and record["dropped"] == ["f^3"]


def test_a_known_edge_slope_or_an_unknown_line_changes_nothing():
    kept = ("f", "f^2", "f^3")
    terms, record = unknown_edge_slope(_windows(5.0, 0.7, 0.05), kept)
    assert terms == kept and record["dropped"] == []
    assert all(abs(s) >= EDGE_SLOPE_Z * e for s, e in (record["cold"], record["hot"]))
    # a flat axis: the line's own slope is unknown, so there is no known sign to keep
    flat = _windows(0.0, 0.0, 2.0)
    assert unknown_edge_slope(flat, kept) == (kept, None)
    # nothing beyond the line
    assert unknown_edge_slope(flat, ("f", "df")) == (("f", "df"), None)


def test_the_model_s_notes_say_why_the_bend_went():
    from types import SimpleNamespace

    from hrgtc.drift.drift_text import drift_notes

    edge = {"line": [8.51, 1.37], "cold": [-3.54, 4.72], "hot": [21.1, 3.22], "z": 2.0,
            "dropped": ["f^2", "f^3"]}
    model = SimpleNamespace(variance_inflation=1.0, bandwidth_windows=0, cross_validation=None,
                            n_not_at_rest=0, offsets_dph={}, pruning={
                                "folds": "coldest and hottest time blocks",
                                "dropped": ["f^2", "f^3"], "before_dph": 9.94,
                                "after_dph": 21.1, "edge_slope": edge})
    notes = drift_notes(model)
    assert notes[0].startswith("guarded selection: dropped f^2, f^3")
    assert notes[1] == ("  f^2, f^3: the slope at an edge of the trained range unknown "
                        "(cold -3.54 ± 4.7, hot 21.1 ± 3.2) where the line's is known "
                        "(8.51 ± 1.4) [°/h per unit of f]")
