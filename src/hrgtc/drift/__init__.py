"""Drift model: stage 2b, the gyro bias from f and df/dt (Eq. 19-22 of [1]).

Takes drift runs (recordings with temperature change) and gives a
:class:`DriftModel`: ``features`` turns frequency into the candidate terms of
Eq. 21 (f, df/dt from a causal filter, the term grammar), ``regression`` and
``stepwise`` select and fit them from a one-pass, mergeable QR factor
(``qr_accumulator``; MATLAB ``stepwisefit`` semantics), ``drift_model`` holds the
fitted model (Eq. 22).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.drift.drift_model import DriftModel, TrainingWindows, fit, window_means
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
from hrgtc.drift.regression import GramAccumulator, OLSResult, ols, ols_from_accumulator, refine
from hrgtc.drift.stepwise import Step, StepwiseResult, stepwise, stepwise_from_accumulator

__all__ = [
    "EQ21",
    "EQ21_TERMS",
    "DriftModel",
    "FeatureSettings",
    "FeatureStream",
    "GramAccumulator",
    "OLSResult",
    "QRAccumulator",
    "Step",
    "StepwiseResult",
    "Term",
    "TrainingWindows",
    "causal_rate",
    "fit",
    "ols",
    "ols_from_accumulator",
    "parse_term",
    "parse_terms",
    "refine",
    "stepwise",
    "stepwise_from_accumulator",
    "window_means",
]
