"""Records of the small results: time events and diagnosis, timeline, gaps, validation
problems and reports, slow channels, rate segments and their scale errors, the QR
accumulator's state and the temperature reference.

Truth: the JSON each wrote before its record (generated with the hand-written
``to_dict`` of commit 648af71 and written out here as literals: keys, order and values
must not change), round trips, the JSON Schema validator (jsonschema, independent of
msgspec) on what each record writes, and refusals naming the place.
"""

from __future__ import annotations

import json

import jsonschema
import numpy as np
import pytest

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.time_steps import (
    TimeDiagnosisRecord,
    TimeEvent,
    classify_time_steps,
)
from hrgtc.core.timeline import Timeline, TimelineRecord
from hrgtc.drift.qr_accumulator import QRAccumulator, QRAccumulatorRecord
from hrgtc.drift.rate_segments import RateSegment, SegmentScaleErrors
from hrgtc.recording.checks import Problem, ValidationReport
from hrgtc.recording.gaps import Gap
from hrgtc.recording.resample import ChannelFill, SlowChannels, SlowChannelsRecord
from hrgtc.thermometry.reference import TemperatureReference, TemperatureReferenceRecord


def _valid(document, record):
    schema = records.json_schema(record, "t", "https://hrgtc.invalid/schema/test.json")
    jsonschema.Draft202012Validator(schema).validate(document)


def _report() -> ValidationReport:
    return ValidationReport(
        False, (Problem("gap", "a gap", "time_s", 3, "7.5", 2), Problem("empty", "no rows")),
        (Gap(2.5, 5.0, 3), Gap(np.float64(20.0), 3.0, 9)), 2, 12, "run.csv", None, "split")


def test_time_diagnosis_layout():
    t = np.concatenate([np.arange(0, 10.0), np.arange(5.0, 8.0), np.arange(100, 103.0)])
    written = classify_time_steps(t, nominal_period_s=1.0).to_dict()
    assert json.dumps(written) == (
        '{"events": [{"kind": "duplicate", "row": 10, "count": 3, "message": "row 10: 3 '
        'duplicated row(s) (same time, same values) dropped", "repaired": true}], '
        '"restarts": [], "duplicates": 3, "period_s": 1.0}')
    _valid(written, TimeDiagnosisRecord)
    event = written["events"][0]
    assert TimeEvent.from_dict(event).to_dict() == event
    with pytest.raises(InputError, match=r"at `\$.row`"):
        TimeEvent.from_dict({**event, "row": -1})
    _valid(event, TimeEvent)


@pytest.mark.parametrize(("time_s", "expected"), [
    (np.concatenate([np.arange(0, 5.0), np.arange(100, 105.0), np.arange(200, 205.0)]),
     '{"segments": 3, "samples": 15, "period_s": 1.0, "gap_factor": 2.0, "span_s": 204.0, '
     '"recorded_s": 15.0, "burst_length_s": 5.0, "burst_period_s": 100.0, "bursty": true}'),
    (np.arange(3.0),
     '{"segments": 1, "samples": 3, "period_s": 1.0, "gap_factor": 2.0, "span_s": 2.0, '
     '"recorded_s": 3.0, "burst_length_s": 3.0, "burst_period_s": null, "bursty": false}'),
    (np.empty(0),
     '{"segments": 0, "samples": 0, "period_s": null, "gap_factor": 2.0, "span_s": 0.0, '
     '"recorded_s": 0.0, "burst_length_s": null, "burst_period_s": null, "bursty": false}'),
], ids=["bursts", "one-segment", "empty"])
def test_timeline_layout(time_s, expected):
    written = Timeline.from_time(time_s, 1.0 if time_s.size > 5 else None).to_dict()
    assert json.dumps(written) == expected
    _valid(written, TimelineRecord)


def test_validation_report_layout_round_trip_and_refusals():
    report = _report()
    written = report.to_dict()
    assert json.dumps(written) == (
        '{"ok": false, "problems": [{"kind": "gap", "message": "a gap", "column": "time_s", '
        '"row": 3, "value": "7.5", "count": 2}, {"kind": "empty", "message": "no rows", '
        '"column": null, "row": null, "value": null, "count": 1}], "gaps": [{"start_time_s": '
        '2.5, "duration_s": 5.0, "row": 3}, {"start_time_s": 20.0, "duration_s": 3.0, '
        '"row": 9}], "n_gaps": 2, "rows": 12, "source": "run.csv", '
        '"measured_sample_rate_hz": null, "gap_policy": "split", "n_dropouts": 0, '
        '"dropout_s": 0.0, "duty_cycled": false}')
    _valid(written, ValidationReport)
    again = ValidationReport.from_dict(json.loads(json.dumps(written)))
    assert again == report and again.to_dict() == written
    assert Problem.from_dict(written["problems"][1]) == report.problems[1]
    assert Gap.from_dict(written["gaps"][0]) == report.gaps[0]
    with pytest.raises(InputError, match=r"at `\$.gaps\[1\].duration_s`"):
        ValidationReport.from_dict({**written, "gaps": [written["gaps"][0],
                                                        {**written["gaps"][1],
                                                         "duration_s": -1.0}]})
    with pytest.raises(InputError, match=r"at `\$.gap_policy`"):
        ValidationReport.from_dict({**written, "gap_policy": "skip"})
    with pytest.raises(InputError, match=r"at `\$.row`"):
        Problem.from_dict({"kind": "gap", "message": "m", "row": "three"})


def test_slow_channels_layout():
    slow = SlowChannels("hold", None, "f.csv")
    slow.channels["chamber_c"] = ChannelFill("chamber_c", 10.0, 50.0, 40, 2, 17)
    slow.channels["freq_hz_x"] = ChannelFill("freq_hz_x", 10.0, 50.0, alias_of="chamber_c")
    slow.channels["housing_c"] = ChannelFill("housing_c", 2.5, 12.5)
    written = slow.to_dict()
    assert json.dumps(written) == (  # the alias of chamber_c is not reported
        '{"mode": "hold", "channels": [{"column": "chamber_c", "period_s": 10.0, '
        '"max_age_s": 50.0, "filled": 40, "dropped": 2, "first_dropped_row": 17}, '
        '{"column": "housing_c", "period_s": 2.5, "max_age_s": 12.5, "filled": 0, '
        '"dropped": 0, "first_dropped_row": null}]}')
    _valid(written, SlowChannelsRecord)


def test_segment_scale_errors_layout_and_round_trip():
    errors = SegmentScaleErrors(
        (RateSegment(10.0, 59.995, 36000.0, 36012.5, 5432.1, 1000, 2000),
         RateSegment(70.0, 119.0, -36000.0, -35990.0, 5432.2, 980)), np.array([347.2, -277.8]))
    written = errors.to_dict()
    assert json.dumps(written) == (
        '{"segments": [{"start_s": 10.0, "end_s": 59.995, "input_rate_dph": 36000.0, '
        '"rate_dph": 36012.5, "freq_hz": 5432.1, "rows": 1000, "first_row": 2000}, '
        '{"start_s": 70.0, "end_s": 119.0, "input_rate_dph": -36000.0, "rate_dph": '
        '-35990.0, "freq_hz": 5432.2, "rows": 980, "first_row": 0}], '
        '"error_ppm": [347.2, -277.8]}')
    _valid(written, SegmentScaleErrors)
    again = SegmentScaleErrors.from_dict(json.loads(json.dumps(written)))
    assert again.segments == errors.segments
    np.testing.assert_array_equal(again.error_ppm, errors.error_ppm)
    assert RateSegment.from_dict(written["segments"][1]) == errors.segments[1]
    with pytest.raises(InputError, match=r"at `\$.segments\[0\].rows`"):
        SegmentScaleErrors.from_dict({**written, "segments": [
            {**written["segments"][0], "rows": 1.5}]})


def test_qr_accumulator_state_round_trip_is_exact():
    rng = np.random.default_rng(3)
    X = rng.standard_normal((50, 2))
    y = X @ [1.0, 2.0] + 0.1 * rng.standard_normal(50)
    acc = QRAccumulator(["a", "b"]).partial_fit(X, y)
    written = acc.to_dict()
    assert list(written) == ["names", "n", "sum_weights", "shift", "scale", "r"]
    assert written["names"] == ["a", "b"] and written["n"] == 50
    assert written["sum_weights"] == 50.0 and written["scale"] == [1.0, 1.0, 2.0]
    assert written["r"] == acc.r_.tolist()  # every float as it is, -0.0 included
    _valid(written, QRAccumulatorRecord)
    again = QRAccumulator.from_dict(json.loads(json.dumps(written)))
    for name in ("shift_", "scale_", "r_"):
        a, b = getattr(again, name), getattr(acc, name)
        assert a.dtype == np.float64 and a.tobytes() == b.tobytes()
    assert again.fit().params.tobytes() == acc.fit().params.tobytes()
    assert json.dumps(again.to_dict()) == json.dumps(written)
    empty = QRAccumulator().to_dict()
    assert json.dumps(empty) == ('{"names": [], "n": 0, "sum_weights": 0.0, "shift": null, '
                                 '"scale": null, "r": null}')
    assert QRAccumulator.from_dict(empty).names_ is None
    with pytest.raises(InputError, match=r"at `\$.n`"):
        QRAccumulator.from_dict({**written, "n": -3})


def test_temperature_reference_layout_and_round_trip():
    full = TemperatureReference("ref.csv", {"time_s": "Time"}, "F", "15:40", "+01:00", 120.0)
    written = full.to_dict()
    assert json.dumps(written) == ('{"path": "ref.csv", "columns": {"time_s": "Time"}, '
                                   '"unit": "F", "start": "15:40", "tz": "+01:00", '
                                   '"lag_s": 120.0}')
    assert TemperatureReference.from_dict(written) == full
    bare = TemperatureReference("ref.csv")
    assert json.dumps(bare.to_dict()) == ('{"path": "ref.csv", "columns": {}, "unit": null, '
                                          '"start": null, "tz": null, "lag_s": null}')
    assert TemperatureReference.from_dict(bare.to_dict()) == bare
    _valid(written, TemperatureReferenceRecord)
    with pytest.raises(InputError, match=r"at `\$.lag_s`"):
        TemperatureReference.from_dict({**written, "lag_s": "late"})
