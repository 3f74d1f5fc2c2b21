"""hrgtc: temperature-drift compensation of hemispherical resonator gyros.

The method is that of [1]: the resonator's natural frequency is a thermometer
(Eq. 16-18, Tables 1-2) and the gyro bias is modelled from the frequency change
and its rate by stepwise linear regression (Eq. 19-22).

The pipeline, one package per stage, imports flowing one way::

    recording -> thermometry, drift -> model -> compensate -> evaluation -> report
              -> calibration, demo -> cli

Importing ``hrgtc`` itself loads none of the stages (the command line starts fast);
import the stage you need, e.g. ``from hrgtc.pipeline.calibration import calibrate``.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from hrgtc.core.meta import PAPER_REFERENCE

if TYPE_CHECKING:
    from hrgtc.model import Model

__all__ = ["PAPER_REFERENCE", "__version__", "load_model"]


def __getattr__(name: str) -> Any:
    """``hrgtc.__version__``, looked up on first use (:mod:`hrgtc.core.meta`)."""
    if name != "__version__":
        raise AttributeError(f"module 'hrgtc' has no attribute {name!r}")
    from hrgtc.core import meta

    return meta.__version__


def load_model(path: str | os.PathLike[str]) -> Model:
    """Read a model file: :func:`hrgtc.model.load_model`, imported when first called."""
    from hrgtc.model import load_model as _load_model

    return _load_model(path)
