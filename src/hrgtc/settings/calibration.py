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
class PlateauSettings:
    """How the soak plateaus are found and settled (:func:`hrgtc.thermometry.find_plateaus`).

    Not command-line options: the model file's provenance records them.
    """

    slope_threshold_hz_per_h: float = setting(
        0.01, "A stretch is settled once its frequency drifts less than this (0.01 Hz/h = "
        "0.027 °C/h at 0.37 Hz/°C: within ~0.02 °C of equilibrium behind the ~40 min "
        "resonator time constant of [1]).", unit="Hz/h", cli=None)
    min_duration_s: float = setting(
        1800.0, "Shortest stable chamber stretch: ~0.75 resonator time constants, long "
        "enough to resolve 0.01 Hz/h under mHz frequency noise.", unit="s", cli=None)
    chamber_tolerance_c: float = setting(
        0.5, "What a climatic chamber holds around its set-point.", unit="°C", cli=None)
    block_s: float = setting(10.0, "Block means the plateau finder works on.", unit="s",
                             cli=None)
    extrapolate: bool = setting(
        True, "A soak that has not settled is extrapolated by its settling curve.", cli=None)
    hz_per_c: float = setting(
        0.37, "Approximate df/dT, the linear term of Eq. (18) of [1].", unit="Hz/°C",
        cli=None)
    max_fit_std_c: float = setting(
        0.01, "Largest standard error of an extrapolated f_inf, in resonator temperature.",
        unit="°C", cli=None)


@dataclass(frozen=True)
class CalibrationSettings:
    """Everything ``hrgtc calibrate`` tunes: the thermometer, the drift fit and the chain.

    The provenance of a fresh model file records every field (:func:`hrgtc.settings.to_dict`).
    """

    thermometer: ThermometerSettings = field(default_factory=ThermometerSettings)
    plateaus: PlateauSettings = field(default_factory=PlateauSettings)
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
