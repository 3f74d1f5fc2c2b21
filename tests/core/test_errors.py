"""Tests of hrgtc.core.errors: messages say numbers as numbers (issue 21: ``np.float64(…)`` in
messages). The fix is at the root, in the base classes, so the test samples real errors
raised with numpy scalars in their ``!r`` fields from several packages, and the cleaning
itself."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc.core.errors import (
    ExtrapolationWarning,
    HrgtcError,
    InputError,
    ModelFileError,
    OutputExistsError,
    plain,
)


@pytest.mark.parametrize("value, text", [
    (np.float64(4417.25), "4417.25"),
    (np.float32(2.5), "2.5"),
    (np.int64(-3), "-3"),
    (np.uint8(7), "7"),
    (np.bool_(True), "True"),
    (np.str_("f^2"), "'f^2'"),
    ([np.float64(1.0), np.float64(-0.5)], "[1.0, -0.5]"),
    ((np.float64(np.nan), np.float64(np.inf)), "(nan, inf)"),
])
def test_numpy_scalars_read_as_numbers_in_every_error(value, text):
    for kind in (HrgtcError, InputError, ModelFileError):
        message = str(kind(f"got {value!r} here"))
        assert message == f"got {text} here"
        assert "np." not in message
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.warn(ExtrapolationWarning(f"seen {value!r}"), stacklevel=1)
    assert str(caught[0].message) == f"seen {text}"


def test_plain_leaves_other_text_alone():
    text = "np.where(x) and numpy.float64 and np.float64 (no call) and np.float64(f(x))"
    assert plain(text) == text
    assert str(OutputExistsError(17, "out.parquet exists")) == "[Errno 17] out.parquet exists"


def test_a_sample_of_real_errors_has_no_numpy_repr():
    """Errors of the reading, drift, compensation and simulation packages raised with numpy
    scalars where users pass them (a value from an array) say plain numbers."""
    from hrgtc.compensate import Compensator
    from hrgtc.drift.features import parse_term
    from hrgtc.model import Model
    from hrgtc.recording import Metadata, Recording
    from hrgtc.simulate.standard_profiles import cooldown

    from fuzzing import make_model, make_run

    messages = []
    for call in (
        lambda: Metadata(sample_rate_hz=np.float64(-5.0)),
        lambda: parse_term(np.str_("q^2")),
        lambda: cooldown(np.float64(-20.0), np.float64(20.0), np.float64(2.0)),
    ):
        with pytest.raises(HrgtcError) as raised:
            call()
        messages.append(str(raised.value))
    run = make_run(rows=200)
    columns = {"time_s": run.time_s, "freq_hz_x": run.freq_hz * 3.0, "rate_dph_x": run.rate_dph}
    compensator = Compensator(Model({"x": make_model().axis}),
                                        bands_hz={"x": (4000.0, 5000.0)})
    with pytest.raises(HrgtcError) as raised:
        compensator.transform(Recording(columns, run.metadata))
    messages.append(str(raised.value))
    for message in messages:
        assert "np." not in message, message
    assert "-5.0" in messages[0] and "'q'" in messages[1] and "-20.0" in messages[2]
