"""Exception and warning classes of hrgtc.

Every error the library raises on purpose derives from :class:`HrgtcError`, every
warning from :class:`HrgtcWarning`, so a caller can catch the whole family.
"""

from __future__ import annotations


class HrgtcError(Exception):
    """Base class of all errors raised by hrgtc."""


class InputError(HrgtcError, ValueError):
    """Arguments that are contradictory or unusable (wrong shape, too few points, ...)."""


class RecordingError(InputError):
    """A recording that breaks the recording contract (missing column, NaN, bad time, ...)."""


class CalibrationError(HrgtcError):
    """A calibration the data cannot support (no plateau, non-monotonic f(T), ...)."""


class RankDeficientError(HrgtcError, ValueError):
    """A regression whose design matrix is rank deficient or too collinear to solve."""


class ModelFileError(HrgtcError):
    """A model file that is unreadable, corrupt, foreign or of a newer schema."""


class OutputExistsError(HrgtcError, FileExistsError):
    """An output file exists and overwriting it was not allowed (pass force=True / --force)."""


class HrgtcWarning(UserWarning):
    """Base class of all warnings issued by hrgtc."""


class ExtrapolationWarning(HrgtcWarning):
    """Input is valid but outside the range a model was calibrated on."""


class SpikeWarning(HrgtcWarning):
    """Rows of implausible samples were dropped from a recording (``spikes="drop"``)."""


class PrecisionWarning(HrgtcWarning):
    """A computation ran at lower precision than asked (no extended-precision type here)."""


class UnitWarning(HrgtcWarning):
    """Values were reinterpreted on reading (e.g. a signed count stored unsigned, unwrapped)."""
