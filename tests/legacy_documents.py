"""The hand-written JSON documents of the evaluation and calibration results, as they were
before their records (``Evaluation``, ``BurstAllanResult``, ``DirectionStats``,
``ResidualResult``, ``ScaleFactorCheck``, ``AxisCalibration``, ``Calibration``,
``RunEvaluation``): the reference the records' documents must equal, key for key and
in order (tests/evaluation/test_result_records.py, tests/pipeline/test_calibration_records.py).

The only difference allowed: a number that is not finite, which these wrote as NaN (not
JSON) and a record writes as null (:func:`strict`).
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

import numpy as np

from hrgtc.evaluation.deviation_curves import _curve, _finite
from hrgtc.evaluation.metrics import table_to_json

DIRECTIONS = ("heating", "cooling")


def strict(value: Any) -> Any:
    """``value`` with every float that is not finite as None (what a record writes)."""
    if isinstance(value, dict):
        return {k: strict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [strict(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def residual(self) -> dict[str, Any]:
    return {**asdict(self), "bias_stability_dph": table_to_json(self.bias_stability_dph)}


def burst_allan(self) -> dict[str, Any]:
    def plain(value: Any) -> Any:
        if isinstance(value, np.ndarray):
            return [None if isinstance(v, float) and not math.isfinite(v) else v
                    for v in value.tolist()]
        return value
    return {k: plain(v) for k, v in asdict(self).items()}


def directions(self) -> dict[str, Any]:
    def clean(v: float) -> float | None:
        return float(v) if math.isfinite(v) else None

    return {d: {"blocks": self.blocks[d], "raw_dph": clean(self.raw_dph[d]),
                "compensated_dph": clean(self.compensated_dph[d]),
                "improvement": clean(self.improvement(d)),
                "residual_rms_dph": None if self.residual_rms_dph is None
                else clean(self.residual_rms_dph[d])}
            for d in DIRECTIONS} | {"block_s": self.block_s,
                                    "partial_blocks": self.partial_blocks,
                                    "reason": self.reason}


def evaluation(self) -> dict[str, Any]:
    table: dict[str, Any] = {k: table_to_json(v) for k, v in self.bias_stability_dph.items()}
    table.setdefault("housing", None)
    noise = {k: {name: (_finite(value) if isinstance(value, float) else value)
                 for name, value in terms.to_dict().items()}
             for k, terms in self.noise.items()}
    return {
        "file": self.file,
        "n_samples": self.n_samples,
        "sample_rate_hz": self.sample_rate_hz,
        "bias_stability_dph": table,
        "bias_stability_10s_dph": {"raw": _finite(self.raw_10s),
                                   "compensated": _finite(self.compensated_10s)},
        "improvement_10s": _finite(self.improvement_10s),
        "mean_dph": {k: _finite(v) for k, v in self.mean_dph.items()},
        "rms_dph": {k: _finite(v) for k, v in self.rms_dph.items()},
        "n_not_at_rest": self.n_not_at_rest,
        "allan": noise,
        "deviation": self.deviation,
        "allan_curve": {k: _curve(a) for k, a in self.allan.items()},
        "confidence": self.confidence,
        "bias_stability_interval_dph": {
            k: {f"{t:g}": (None if math.isnan(b[0]) else [float(b[0]), float(b[1])])
                for t, b in row.items()}
            for k, row in self.bias_stability_interval_dph.items()},
        "bias_stability_n": {k: {f"{t:g}": int(c) for t, c in row.items()}
                             for k, row in self.bias_stability_blocks.items()},
        "allan_burst_means": {k: burst_allan(b) for k, b in self.burst_allan.items()},
        "prediction_std_dph": self.prediction_std_dph,
        "out_of_range_fraction": self.out_of_range_fraction,
        "rate_out_of_range_fraction": self.rate_out_of_range_fraction,
        "residual_rms_dph": self.residual_rms_dph,
        "ranges": None if self.ranges is None else self.ranges.to_dict(),
        "notes": list(self.notes),
        "heating_cooling": None if self.directions is None else directions(self.directions),
        "accounting": None if self.accounting is None else self.accounting.to_dict(),
    }


def scale_check(self) -> dict[str, Any]:
    return {"file": self.file, "axis": self.axis, "freq_hz": list(self.freq_hz),
            "holds": list(self.holds), "raw_ppm": list(self.raw_ppm),
            "compensated_ppm": list(self.compensated_ppm),
            "raw_max_ppm": self.raw_max_ppm, "compensated_max_ppm": self.compensated_max_ppm}


def calibration(self) -> dict[str, Any]:
    d = self.model.drift
    return {
        "thermometer": {
            "coefficients_high_first": list(self.model.thermometer.coefficients_high_first),
            "standard_errors_high_first": [
                None if not np.isfinite(v) else v
                for v in reversed(self.model.thermometer.standard_errors)
            ],
            "table": [dict(row) for row in self.table],
        },
        "drift": {
            "selected_terms": list(d.selected),
            "history": [s.to_dict() for s in d.history],
            "intercept_dph": d.intercept_dph,
            "coefficients": dict(d.coefficients),
            "standard_errors": dict(d.standard_errors),
            "pvalues": dict(d.pvalues),
            "window_s": d.window_s,
            "n_windows": d.n_windows,
            "selection": d.selection,
            "n_not_at_rest": d.n_not_at_rest,
            "offset_mode": d.offset_mode,
            "offsets_dph": dict(d.offsets_dph),
            "pruning": d.pruning,
            "cross_validation": None if d.cross_validation is None
            else d.cross_validation.to_dict(),
            "accounting": None if d.accounting is None else d.accounting.to_dict(),
        },
        "housing": None if self.model.housing is None else {
            "selected_terms": list(self.model.housing.selected),
            "coefficients": dict(self.model.housing.coefficients),
        },
        "validation": [evaluation(v) for v in self.validation],
        "prior": None if self.prior_fit is None else self.prior_fit.to_dict(),
    }


def instrument(self) -> dict[str, Any]:
    axes = {}
    for axis, result in self.axes.items():
        entry = calibration(result)
        entry["validation"] = [evaluation(v) for v in self.axes[axis].validation]
        sf = self.model.axes[axis].scale_factor
        entry["scale_factor"] = None if sf is None else sf.to_dict()
        axes[axis or "-"] = entry
    return {"unit": self.model.unit, "axes": axes,
            "scale_factor_checks": [scale_check(c) for c in self.scale_checks],
            "cross_axis": dict(self.cross_axis)}


def instrument_document(self) -> dict[str, Any]:
    single = self.model.is_single_axis
    if single and not self.scale_checks and self.model.axes[""].scale_factor is None:
        document = calibration(self.axes[""])
    else:
        document = instrument(self)
    if single:
        document["validation"] = [evaluation(v) for v in self.axes[""].validation]
    if self.model.temperature_map is not None:
        document["temperature_map"] = dict(self.model.temperature_map)
    return document


def instrument_evaluation(self) -> dict[str, Any]:
    if self.model.is_single_axis:
        return evaluation(self.axes[""])
    summary = [{k: None if isinstance(v, float) and not np.isfinite(v) else v
                for k, v in row.items()} for row in self.axis_summary()]
    return {"unit": self.model.unit,
            "axes": {a: evaluation(r) for a, r in self.axes.items()}, "summary": summary}
