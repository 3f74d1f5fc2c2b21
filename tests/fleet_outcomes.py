"""Fixed outcomes for the fleet table's pin (``tests/data/fleet-table/make.py``)."""

from __future__ import annotations

from hrgtc.fleet.tasks import UnitOutcome

_CALIBRATED = {
    "unit": "u-001", "model_file": "models/u-001.json", "n_soaks": 5,
    "temperature_low_c": -20.0, "temperature_high_c": 60.0,
    "centre_c": 20.0, "scale_c": 40.0,
    "coefficients_high_first": [1.2e-5, -9.7e-4, 0.3715, 4424.9],
    "freq_centre_hz": 4432.1, "relative_coefficients": [1.0, 3.3e-3, -8.7e-6, 1.2e-7],
    "f20_hz": 4431.7, "tcf_ppm_per_c": 80.5,
    "soak_temperatures_c": [-20.0, 0.0, 20.0, 40.0, 60.0],
    "settled_freqs_hz": [4417.6, 4424.9, 4431.7, 4438.3, 4445.1],
    "table_max_error_c": 0.012,
    "terms_kept": ["T", "dT", "T^2"], "n_terms": 3,
    "runs": ["held-1.parquet", "held-2.parquet"],
    "raw_10s_dph": [3.01, 2.5], "compensated_10s_dph": [0.58, None],
    "improvement_10s": [5.2, None], "out_of_range_fraction": [0.0, 0.125],
    "rate_out_of_range_fraction": [0.0, 0.5], "median_improvement_10s": 5.2,
    "not_a_column": "dropped",
}

OUTCOMES = [
    UnitOutcome(unit="u-002", status="failed", seconds=1.5,
                error={"type": "InputError", "message": "bad column", "file": "u-002.csv",
                       "column": "freq_hz", "row": 17, "traceback": ("x",)}),
    UnitOutcome(unit="u-001", status="ok", row=_CALIBRATED, seconds=12.25),
    UnitOutcome(unit="u-003", status="failed", seconds=0.0,
                error={"type": "RuntimeError", "message": "worker died"}),
]
