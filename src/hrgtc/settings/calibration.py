"""Settings of the calibration chain: soaks -> thermometer, ramps -> drift model, scale factor."""

from __future__ import annotations

from dataclasses import dataclass, field

from hrgtc.settings import setting
from hrgtc.settings.drift import DriftSettings

_CAL = "Calibration"
#: Cross-axis candidates are kept when the held-out 10 s bias stability drops by more.
CROSS_AXIS_GAIN = 0.02


@dataclass(frozen=True)
class ThermometerSettings:
    """How the thermometer f(T) is fitted to the soak plateaus (Eq. 18 of [1])."""

    order: int = setting(3, "Order of the thermometer polynomial f(T) (3 in [1]).",
                         panel=_CAL)


@dataclass(frozen=True)
class CalibrationSettings:
    """Everything ``hrgtc calibrate`` tunes: the thermometer, the drift fit and the chain.

    The provenance of a fresh model file records every field (:func:`hrgtc.settings.to_dict`).
    """

    thermometer: ThermometerSettings = field(default_factory=ThermometerSettings)
    drift: DriftSettings = field(default_factory=DriftSettings)
    drift_from_soaks: bool = setting(
        True, "Also fit the drift model on the soaks' warming and cooling transients.",
        cli="--drift-from-soaks/--no-drift-from-soaks", panel=_CAL)
    scale_terms: tuple[str, ...] = setting(
        ("f", "f^2", "f^3"), "Candidate terms of the scale-factor model, comma separated.",
        panel=_CAL)
    cross_axis: bool = setting(
        False, "Several axes: also try the other resonators' frequencies as candidate terms "
        "of each axis (gradients across the unit); kept per axis only where the --validate "
        "runs improve by more than "
        f"{CROSS_AXIS_GAIN:.0%}.", panel=_CAL)
