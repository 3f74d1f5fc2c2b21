"""The simulator's ground truth through its records: the same JSON text as before them.

Truth: ``tests/data/simulate-truth/units.json``, written by the commit before the
records (c8c688c, ``make.py`` beside it): every standard unit's ``to_dict`` as JSON text.
"""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.simulate import units
from hrgtc.simulate.laws import (
    BiasLaw,
    PolynomialFrequencyLawRecord,
    ScaleFactorLaw,
    ShellFrequencyLawRecord,
)
from hrgtc.simulate.noise_sources import GyroNoise
from hrgtc.simulate.thermal import ThermalNetwork

TRUTH = Path(__file__).parents[1] / "data" / "simulate-truth" / "units.json"


def test_every_standard_unit_writes_the_same_truth_as_before():
    expected = TRUTH.read_text(encoding="utf-8")
    before = list(json.loads(expected))
    truth = {name: units.get(name).to_dict() for name in before}
    assert json.dumps(truth, indent=1) + "\n" == expected
    # the units added since (their truth: tests/simulate/test_history.py)
    assert set(units.names()) - set(before) == {"unit-play"}


@pytest.mark.parametrize("name", units.names())
def test_truth_round_trips_and_fits_the_records_schemas(name):
    unit = units.get(name)
    written = json.loads(json.dumps(unit.to_dict()))
    assert units.unit_from_dict(written).to_dict() == written
    axes = written["axes"].values() if "axes" in written else [written]
    law_records = {"polynomial": PolynomialFrequencyLawRecord, "shell": ShellFrequencyLawRecord}
    for axis in axes:
        for part, record in ((axis["thermal"], ThermalNetwork),
                             (axis["bias_law"], BiasLaw),
                             (axis["gyro_noise"], GyroNoise),
                             (axis["frequency_law"], law_records[axis["frequency_law"]["kind"]]),
                             (axis.get("scale_factor_law"), ScaleFactorLaw)):
            if part is not None:
                schema = records.json_schema(record, "t", "https://hrgtc.invalid/t.json")
                jsonschema.Draft202012Validator(schema).validate(part)


def test_truth_refusals_name_the_place():
    with pytest.raises(InputError, match=r"`\$.tau_housing_s`"):
        ThermalNetwork.from_dict({"tau_housing_s": 0.0, "tau_resonator_s": 2400.0})
    with pytest.raises(InputError, match=r"unknown field `colour`"):
        ThermalNetwork.from_dict({"tau_housing_s": 720.0, "tau_resonator_s": 2400.0,
                                  "colour": "red"})
    with pytest.raises(InputError, match=r"`\$.flicker_per_decade`"):
        GyroNoise.from_dict({"arw_deg_per_sqrt_h": 0.02, "bias_instability_dph": 0.2,
                             "rrw_dph_per_sqrt_h": 0.1, "flicker_per_decade": 0})
    with pytest.raises(InputError, match=r"`\$.temperature_dph`"):
        BiasLaw.from_dict({"bias0_dph": 1.0, "temperature_dph": [0.1, 0.2]})


@pytest.mark.parametrize("name", units.names())
def test_a_whole_unit_fits_its_records_schema(name):
    written = json.loads(json.dumps(units.get(name).to_dict()))
    record = units.MultiAxisUnitRecord if "axes" in written else units.UnitRecord
    schema = records.json_schema(record, "unit", "https://hrgtc.invalid/unit.json")
    jsonschema.Draft202012Validator(schema).validate(written)
    # the frequency law is one of two kinds, told by its tag
    laws = schema["$defs"]["UnitRecord"]["properties"]["frequency_law"]
    assert laws["discriminator"]["propertyName"] == "kind"
    assert sorted(laws["discriminator"]["mapping"]) == ["polynomial", "shell"]


def test_unit_refusals_name_the_place():
    paper = units.get("paper-unit").to_dict()
    with pytest.raises(InputError, match=r"Invalid value 'spline' - at `\$.frequency_law.kind`"):
        units.unit_from_dict({**paper, "frequency_law": {"kind": "spline"}})
    with pytest.raises(InputError, match=r"`\$.housing_noise_c`"):
        units.unit_from_dict({**paper, "housing_noise_c": -1.0})
    imu = units.get("imu-3").to_dict()
    x = {**imu["axes"]["x"], "bias_law": {"bias0_dph": 1.0, "temperature_dph": [0.1]}}
    with pytest.raises(InputError, match=r"axis 'x' record: .* - at `\$.bias_law.temperature_dph`"):
        units.unit_from_dict({**imu, "axes": {**imu["axes"], "x": x}})
    with pytest.raises(InputError, match=r"`\$.axes`"):
        units.unit_from_dict({**imu, "axes": {}})


def test_a_written_file_round_trips_and_refuses_a_negative_row_count():
    from hrgtc.simulate.output import WrittenFile

    written = WrittenFile(path="runs/soak.parquet", rows=1200, profile="soak 20 C, 5 h")
    document = written.to_dict()
    assert json.dumps(document) == ('{"path": "runs/soak.parquet", "rows": 1200, '
                                    '"profile": "soak 20 C, 5 h"}')
    assert WrittenFile.from_dict(json.loads(json.dumps(document))) == written
    schema = records.json_schema(WrittenFile, "w", "https://hrgtc.invalid/w.json")
    jsonschema.Draft202012Validator(schema).validate(document)
    with pytest.raises(InputError, match=r"`\$.rows`"):
        WrittenFile.from_dict({**document, "rows": -1})
