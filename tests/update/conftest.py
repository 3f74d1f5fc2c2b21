"""Fixtures of the in-field update's tests: the parent model (calibrated on the shared
paper-unit campaign), a model freshly calibrated on the aged unit, field recordings."""

from __future__ import annotations

from pathlib import Path

import pytest

from campaign import SETPOINTS_C
from field_ageing import INPUT_RATE_DPH, aged_unit, field_profile

#: Sample rate of the field recordings (the physics does not depend on it). [Hz]
FIELD_RATE_HZ = 2.0


@pytest.fixture(scope="session")
def parent_file(paper_campaign, tmp_path_factory):
    """The model calibrated on the paper-unit's chamber campaign, in its file."""
    from hrgtc.model import save_model
    from hrgtc.pipeline.calibration import calibrate

    model = calibrate(paper_campaign.soaks, [paper_campaign.cooldown]).model
    return save_model(model, tmp_path_factory.mktemp("parent") / "unit.json")


@pytest.fixture(scope="session")
def parent(parent_file):
    from hrgtc.model import load_model

    return load_model(parent_file)


@pytest.fixture(scope="session")
def fresh(tmp_path_factory):
    """The model of the aged unit freshly calibrated in the chamber (the same campaign as
    the parent's, the aged unit in the chamber)."""
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    folder = tmp_path_factory.mktemp("aged-campaign")
    unit = aged_unit()
    soaks = simulate_files([profiles.soak(sp, 5.0) for sp in SETPOINTS_C], folder / "soaks",
                           "parquet", unit=unit, sample_rate_hz=FIELD_RATE_HZ, seed=21)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], folder / "cool", "parquet",
                          unit=unit, sample_rate_hz=FIELD_RATE_HZ, seed=22)
    return calibrate([w.path for w in soaks], [cool[0].path]).model


#: The field day's seed.
FIELD_SEED = 8


@pytest.fixture(scope="session")
def field_recording():
    """A day in the field of the aged unit: still at 20, 5, -10 and 30 °C (seed 8: an update
    that is applied; on seed 7's day the bias's wander hides the ageing from the held-out
    blocks, and the update is refused for no gain)."""
    from hrgtc.simulate import simulate_run

    return simulate_run(field_profile(), aged_unit(), sample_rate_hz=FIELD_RATE_HZ, seed=FIELD_SEED)


@pytest.fixture(scope="session")
def field_file(tmp_path_factory):
    """The same day as a Parquet file."""
    from hrgtc.simulate import simulate_files

    written = simulate_files([field_profile()], tmp_path_factory.mktemp("field") / "field.parquet",
                             unit=aged_unit(), sample_rate_hz=FIELD_RATE_HZ, seed=FIELD_SEED)
    return Path(written[0].path)


@pytest.fixture(scope="session")
def known():
    """Update settings with the simulator's known input rate (the offset is updated)."""
    from hrgtc.update import UpdateSettings

    return UpdateSettings(input_rate_dph=INPUT_RATE_DPH)


@pytest.fixture(scope="session")
def instrument(imu_campaign):
    """The three-axis ``imu-3`` calibrated on the shared campaign (as the demo does)."""
    import warnings

    from hrgtc.core.errors import HrgtcWarning
    from hrgtc.pipeline.calibration import RateTables, calibrate

    files = imu_campaign
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HrgtcWarning)
        return calibrate(files.soaks, [files.cooldown], [files.warmup],
                         rate_tables=RateTables(runs=(files.rate_table,))).model
