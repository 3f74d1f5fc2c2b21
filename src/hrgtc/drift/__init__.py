"""Drift model: stage 2b, the gyro bias from f and df/dt (Eq. 19-22 of [1]).

Takes drift runs (recordings with temperature change) and gives a
:class:`DriftModel`: ``features`` turns frequency into the candidate terms of
Eq. 21 (f, df/dt from a causal filter, the term grammar), ``regression`` and
``stepwise`` select and fit them from a one-pass, mergeable QR factor
(``qr_accumulator``; MATLAB ``stepwisefit`` semantics), ``drift_model`` holds the
fitted model (Eq. 22). ``rate_segments`` finds the holds of rate-table runs and
``scale_factor`` fits the scale-factor error k(f) from them, stepwise like the bias.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.drift.drift_model import DriftModel, FitRequest, fit, fit_jointly
from hrgtc.drift.features import (
    EQ21,
    EQ21_TERMS,
    FeatureSettings,
    FeatureStream,
    Term,
    causal_rate,
    parse_term,
    parse_terms,
)
from hrgtc.drift.qr_accumulator import QRAccumulator
from hrgtc.drift.rate_segments import (
    RateSegment,
    RateStep,
    SegmentScaleErrors,
    find_rate_segments,
    read_segment_table,
    segment_scale_errors,
)
from hrgtc.drift.regression import GramAccumulator, OLSResult, ols, ols_from_accumulator, refine
from hrgtc.drift.scale_factor import (
    SCALE_FACTOR_JSON_SCHEMA,
    ScaleFactorModel,
    ScaleGroup,
    fit_group,
    fit_scale_factor,
    group_segments,
)
from hrgtc.drift.stepwise import (
    Step,
    StepwiseResult,
    StepwiseRules,
    stepwise,
    stepwise_from_accumulator,
)
from hrgtc.drift.windows import TrainingWindows, Windowing, window_means

__all__ = [
    "EQ21",
    "EQ21_TERMS",
    "SCALE_FACTOR_JSON_SCHEMA",
    "DriftModel",
    "FeatureSettings",
    "FeatureStream",
    "FitRequest",
    "GramAccumulator",
    "OLSResult",
    "QRAccumulator",
    "RateSegment",
    "RateStep",
    "ScaleFactorModel",
    "ScaleGroup",
    "SegmentScaleErrors",
    "Step",
    "StepwiseResult",
    "StepwiseRules",
    "Term",
    "TrainingWindows",
    "Windowing",
    "causal_rate",
    "find_rate_segments",
    "fit",
    "fit_group",
    "fit_jointly",
    "fit_scale_factor",
    "group_segments",
    "ols",
    "ols_from_accumulator",
    "parse_term",
    "parse_terms",
    "read_segment_table",
    "refine",
    "segment_scale_errors",
    "stepwise",
    "stepwise_from_accumulator",
    "window_means",
]
