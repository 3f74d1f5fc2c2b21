"""Settings of an in-field update of a model (``hrgtc update``, :meth:`hrgtc.model.Model.update`).

The update is a Kalman filter on the drift model's offset B0 and, when the still data span
enough temperature, its slope (the term ``f``), fed by the means of still blocks of a new
recording (docs/guide/update.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: The Earth's rotation rate, 7.2921159e-5 rad/s (IERS), in °/h: the magnitude of the input
#: rate vector of a triad at rest.
EARTH_RATE_DPH = 15.0410687
#: Largest Earth-rate projection on an HRG's sensitive axis (15.04 °/h at the poles):
#: the bound of the constant a still mean holds beside the bias when the input is unknown.
EARTH_RATE_BOUND_DPH = 15.0


@dataclass(frozen=True)
class UpdateSettings:
    """What an in-field update uses and what it refuses (:func:`hrgtc.update.update_model`)."""

    input_rate_dph: float | None = setting(
        None, "The known rate on the sensitive axis during the still periods (its "
        "Earth-rate projection): only with it is the offset B0 updated; without it a "
        "still mean is bias + an unknown Earth-rate projection + turn-on shift, and only "
        "the slope is. On the command line: the reading option --input-rate-dph.",
        unit="°/h", default_text="unknown: slope only", cli=None)
    min_span_c: float = setting(
        10.0, "The slope (term f) is updated only when the still blocks' temperatures span "
        "at least this much.", unit="°C", min=0.0)
    block_s: float = setting(
        600.0, "Length of a still block: each still period is cut into blocks, each "
        "block's mean one observation of the filter.", unit="s", min=1.0)
    max_temperature_rate_c_per_h: float = setting(
        2.0, "A block whose temperature changes faster is thermally unsettled (a ramp) and "
        "not used: its residual is the model's transient, not ageing.", unit="°C/h",
        min=0.0)
    ageing_offset_dph: float = setting(
        1.0, "1σ of the offset's ageing since calibration, added to the calibration's "
        "covariance in the prior (and the bound of the process noise).", unit="°/h",
        min=0.0)
    ageing_slope_dph_per_c: float = setting(
        0.02, "1σ of the slope's ageing since calibration, per °C of resonator "
        "temperature.", unit="°/h/°C", min=0.0)
    ageing_tau_h: float = setting(
        720.0, "Time constant of the process noise: the covariance relaxes towards the "
        "prior's with it and never exceeds it (0: no process noise).", unit="h", min=0.0)
    turn_on_dph: float = setting(
        0.3, "1σ of the turn-on shift (the unit's run-to-run repeatability): a nuisance "
        "constant of each recording, not a jump.", unit="°/h", min=0.0)
    max_step_sigma: float = setting(
        5.0, "Refuse an update whose step from the prior is longer than this (Mahalanobis "
        "distance in the prior's metric).", min=0.0)
    jump_sigma: float = setting(
        8.0, "Refuse a recording whose still residual steps within a stretch of "
        "consecutive still blocks by more than this many standard errors (a jump is not "
        "ageing).", min=0.0)
    triad_rate_norm_dph: float = setting(
        EARTH_RATE_DPH, "A model of three orthogonal axes (a triad) without a known input "
        "rate: the magnitude of the rate vector during the still periods, whose direction "
        "is not known; the offsets are updated from it when the still periods hold enough "
        "orientations (the Earth rate at rest; 0: never).", unit="°/h", min=0.0)
    triad_min_orientations: int = setting(
        3, "A triad's offsets are updated from |Ω| only when the still periods hold at "
        "least this many distinct orientations.", min=3)
    triad_max_condition: float = setting(
        100.0, "A triad's offsets are updated from |Ω| only when the condition number of the "
        "still periods' information about them is at most this (orientations about one "
        "axis leave a direction unknown).",
        min=1.0)
    holdout_every: int = setting(
        3, "Every n-th still block (in time) is held out to judge the update, the others "
        "fit it; no update is applied without a gain on the held-out blocks.", min=2)
