"""Exception and warning classes of hrgtc.

Every error the library raises on purpose derives from :class:`HrgtcError`, every
warning from :class:`HrgtcWarning`, so a caller can catch the whole family.
"""

from __future__ import annotations

import re
from typing import Any

#: ``np.float64(1.5)``, ``np.int64(3)``, ``np.str_('x')``, ``np.True_``: the repr of numpy
#: scalars (numpy >= 2), which an f-string's ``!r`` puts into a message.
_NUMPY_REPR = re.compile(r"\bnp\.(?:float|int|uint|complex|bool|str|bytes)\w*\(([^()]*)\)")
_NUMPY_BOOL = re.compile(r"\bnp\.(True|False)_")


def plain(message: str) -> str:
    """``message`` with every numpy scalar repr (``np.float64(1.5)``) as the number (``1.5``).

    Examples
    --------
    >>> plain("row 3: np.float64(4417.5) Hz, np.int64(2) rows, np.True_")
    'row 3: 4417.5 Hz, 2 rows, True'
    """
    return _NUMPY_BOOL.sub(r"\1", _NUMPY_REPR.sub(r"\1", message))


def _cleaned(args: tuple[Any, ...]) -> tuple[Any, ...]:
    return tuple(plain(a) if isinstance(a, str) else a for a in args)


class HrgtcError(Exception):
    """Base class of all errors raised by hrgtc.

    Its message never shows numpy's scalar repr: ``np.float64(4417.5)`` in an f-string's
    ``!r`` reads ``4417.5`` (:func:`plain`), for every error of the package at once.
    """

    def __init__(self, *args: Any) -> None:
        super().__init__(*_cleaned(args))


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


class UpdateRefusedError(InputError):
    """An in-field update of a model that must not be applied (another unit's file, a jump,
    a ramp, no held-out gain, a step too far from the prior); the message says which."""


class OutputExistsError(HrgtcError, FileExistsError):
    """An output file exists and overwriting it was not allowed (pass force=True / --force)."""


class HrgtcWarning(UserWarning):
    """Base class of all warnings issued by hrgtc (messages cleaned as :class:`HrgtcError`'s)."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*_cleaned(args))


class CompensationWarning(HrgtcWarning):
    """Compensation made a run's bias stability worse than the raw output's, beyond their
    intervals: the model does not hold on that run."""


class ExtrapolationWarning(HrgtcWarning):
    """Input is valid but outside the range a model was calibrated on."""


class SpikeWarning(HrgtcWarning):
    """Rows of implausible samples were dropped from a recording (``spikes="drop"``)."""


class PrecisionWarning(HrgtcWarning):
    """A computation ran at lower precision than asked (no extended-precision type here)."""


class UnitWarning(HrgtcWarning):
    """Values were reinterpreted on reading (e.g. a signed count stored unsigned, unwrapped)."""


class RateFilterWarning(HrgtcWarning):
    """The causal df/dt filter cannot follow the recording: the thermometer's quantisation
    makes the df/dt noise larger than the df/dt signal at its time constant."""


class GapWarning(HrgtcWarning):
    """A recording's time axis was mended without being asked: a duty-cycled logger's
    gaps or short dropouts bridged, a logger restart read as a new run."""


class SlowChannelWarning(HrgtcWarning):
    """A channel logged slower than the file's rows was filled (held or interpolated) and
    rows farther than the maximum age from its values were dropped as a gap."""


class FormatPluginWarning(HrgtcWarning):
    """A file format of another package (entry point ``hrgtc.formats``) could not be loaded
    and was left out; the other formats are read as usual."""


class CommandPluginWarning(HrgtcWarning):
    """A command of another package (entry point ``hrgtc.commands``) could not be loaded, or
    takes a name already taken, and was left out; the other commands run as usual."""
