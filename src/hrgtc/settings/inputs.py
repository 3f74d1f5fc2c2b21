"""Settings of what ``hrgtc calibrate`` takes beside its recordings: inputs, not tuning.

An extra logged channel as a drift variable (``--aux``), a reference log of the
temperature to fit a raw count's map from (``--temp-ref`` and its ``--temp-ref-*``
options) and the held-out end of the one drift file (``--holdout-*``). The fields hold
what the user gave, as plain values; ``hrgtc calibrate`` hands them whole to
:func:`hrgtc.pipeline.calibration.calibrate` (``inputs=``), which turns them into the
library's types (:func:`hrgtc.pipeline.terms.parse_aux`,
:class:`hrgtc.thermometry.reference.TemperatureReference`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from hrgtc.settings import setting

#: Largest lag of the reference log behind the sensor tried either way when it is fitted
#: (:func:`hrgtc.thermometry.reference.fit_count_map`). [s]
MAX_LAG_S = 1800.0


@dataclass(frozen=True)
class TemperatureReferenceSettings:
    """A reference log of the temperature (``--temp-ref``) and how to read it: the fields
    of :class:`hrgtc.thermometry.reference.TemperatureReference`, as given."""

    reference_log: Path | None = setting(  # noqa: RUF009 (setting() is a field)
        None, "Reference log of the temperature (sparse, e.g. a hand log every 5 min) written "
        "beside the first --drift run: fits its raw temperature count's map to °C (residual "
        "printed, the reference's lag fitted), stores it in the model and compensation "
        "applies it. Columns time_s (seconds, clock times HH:MM[:SS] or dates) and "
        "temperature_c by default (--temp-ref-col).", cli="--temp-ref")
    reference_columns: tuple[str, ...] = setting(
        (), "The reference log's columns, e.g. --temp-ref-col time_s=Time --temp-ref-col "
        "'temperature_c=C1 (C)'.", cli="--temp-ref-col", metavar="NAME=THEIRS", multiple=True)
    reference_start: str | None = setting(
        None, "Clock time of the recording's t = 0 (15:40, or 2020-03-07T15:40:00+01:00) when "
        "the log has clock times.", cli="--temp-ref-start", metavar="CLOCK",
        default_text="the recording's first time stamp")
    reference_unit: str | None = setting(
        None, "Unit of the reference temperature.", cli="--temp-ref-unit", metavar="C|F",
        default_text="F when its header says (F), °F or degF, else C")
    reference_tz: str | None = setting(
        None, "Time zone of naive clock times (+01:00, Europe/Berlin) when the other side "
        "carries a UTC offset.", cli="--temp-ref-tz", metavar="ZONE")
    reference_lag_s: float | None = setting(
        None, "The reference's lag behind the sensor.", unit="s", cli="--temp-ref-lag-s",
        default_text=f"fitted within ±{MAX_LAG_S:g} s")

    def described(self) -> list[str]:
        """The options given that describe the log (``--temp-ref-col``, ...), in order:
        with no ``--temp-ref`` they are a mistake."""
        return [option for name, option in _DESCRIBING
                if getattr(self, name) not in (None, ())]


#: The fields that describe the reference log, and their options.
_DESCRIBING = (("reference_columns", "--temp-ref-col"), ("reference_start", "--temp-ref-start"),
               ("reference_unit", "--temp-ref-unit"), ("reference_tz", "--temp-ref-tz"),
               ("reference_lag_s", "--temp-ref-lag-s"))


@dataclass(frozen=True)
class HoldoutSettings:
    """The held-out end of the one drift file (:func:`hrgtc.pipeline.holdout.holdout_split`)."""

    holdout_s: float | None = setting(
        None, "Hold out the last SECONDS of recorded time of the --drift file (cut at a segment "
        "start: a burst is never split) and validate on it.", unit="s")
    holdout_fraction: float | None = setting(
        None, "Hold out this share of the --drift file's recorded time at its end (e.g. 0.25) "
        "and validate on it.")


@dataclass(frozen=True)
class CalibrationInputs:
    """Everything ``hrgtc calibrate`` takes beside its recordings and its tuning
    (:class:`~hrgtc.settings.calibration.CalibrationSettings`)."""

    aux: tuple[str, ...] = setting(
        (), "An extra logged channel (drive amplitude, quadrature control voltage) as variable "
        "a_NAME, centred on its training mean; the term a_NAME joins the candidates. "
        "compensate/evaluate read the same column.", metavar="NAME=COLUMN", multiple=True)
    reference: TemperatureReferenceSettings = field(
        default_factory=TemperatureReferenceSettings)
    holdout: HoldoutSettings = field(default_factory=HoldoutSettings)
