"""Simulated test campaigns with known truth, written to files with their manifests.

The paper-unit (src/hrgtc/simulate/units.py) at 1 Hz: turn-ons at 20 °C on five days,
each with its own turn-on offset and a warm-up transient added to the output and to the
truth; soaks at four temperatures that start settled (so the whole soak is at its
temperature); a cool-down sweep; optionally a rate table of the imu-3's x axis, the
simulator's unit with a scale-factor law. The Earth rate: the simulator adds a constant
input of 10 °/h, the component on an up axis at latitude asin(10 / 15.041067 °/h).
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hrgtc.recording import Recording, write
from hrgtc.simulate import simulate_run
from hrgtc.simulate.standard_profiles import constant, cooldown, rate_table, soak
from hrgtc.testreport.manifest import EARTH_RATE_DPH

#: Turn-on offsets added to the five turn-ons (the day-to-day bias), and the warm-up. [°/h]
TURN_ON_OFFSETS_DPH = (0.6, -0.9, 1.4, -0.3, 0.2)
WARMUP_DPH, WARMUP_TAU_S = 4.0, 300.0
SOAK_SETPOINTS_C = (-20.0, 0.0, 20.0, 40.0)
#: The latitude at which an up axis sees the simulator's 10 °/h. [°]
LATITUDE_DEG = math.degrees(math.asin(10.0 / EARTH_RATE_DPH))


@dataclass(frozen=True)
class CampaignFiles:
    folder: Path
    manifest: Path
    turn_ons: tuple[Path, ...]
    soaks: tuple[Path, ...]
    sweep: Path
    rate_table: Path | None


def _with_offset(recording: Recording, offset: np.ndarray) -> Recording:
    return recording.with_columns(rate_dph=recording.rate_dph + offset,
                                  bias_dph=recording["bias_dph"] + offset)


def write_campaign(folder: Path, *, hours: float = 1.5, with_table: bool = False,
                   model: Path | None = None, settings: str = "") -> CampaignFiles:
    folder.mkdir(parents=True, exist_ok=True)
    turn_ons = []
    for day, offset in enumerate(TURN_ON_OFFSETS_DPH):
        run = simulate_run(constant(20.0, hours), sample_rate_hz=1.0, seed=10 + day)
        time = run.time_s - run.time_s[0]
        run = _with_offset(run, offset + WARMUP_DPH * np.exp(-time / WARMUP_TAU_S))
        turn_ons.append(write(run, folder / f"turnon_day{day + 1}.parquet", force=True))
    soaks = [write(simulate_run(soak(t, hours, start_c=t), sample_rate_hz=1.0, seed=30 + i),
                   folder / f"soak_{t:+.0f}C.parquet", force=True)
             for i, t in enumerate(SOAK_SETPOINTS_C)]
    sweep = write(simulate_run(cooldown(20.0, -20.0, 2.0), sample_rate_hz=1.0, seed=50),
                  folder / "sweep.parquet", force=True)
    table = None
    if with_table:
        from hrgtc.simulate.units import get
        profile = rate_table((0.0, 20.0, 40.0), (10.0, -10.0, 50.0, -50.0), hold_s=120.0,
                             soak_h=2.0, start_c=0.0)
        table = write(simulate_run(profile, get("imu-3").axes["x"], sample_rate_hz=1.0,
                                   seed=60), folder / "table.parquet", force=True)
    runs = [*(f'[[runs]]\nfile = "{p.name}"\nrole = "turn-on"\nday = "2026-11-0{k + 1}"\n'
              for k, p in enumerate(turn_ons)),
            *(f'[[runs]]\nfile = "{p.name}"\nrole = "soak"\n' for p in soaks),
            f'[[runs]]\nfile = "{sweep.name}"\nrole = "sweep"\n']
    if table is not None:
        runs.append(f'[[runs]]\nfile = "{table.name}"\nrole = "rate-table"\n')
    model_line = ""
    if model is not None:
        shutil.copyfile(model, folder / "model.json")
        model_line = 'model = "model.json"\n'
    manifest = folder / "campaign.toml"
    manifest.write_text(f'''title = "Acceptance test <simulated>"
[unit]
serial = "SN-0042"
firmware = "2.3.1"
type = "HRG (simulated paper-unit)"
{model_line}[site]
latitude_deg = {LATITUDE_DEG!r}
axis = "up"
[conditions]
ambient = "23 ± 2 °C"
mounting = "level, on the chamber's fixture"
[[equipment]]
item = "thermal chamber"
id = "TC-07"
certificate = "CAL-2026-0311"
due = "2027-03-01"
[[equipment]]
item = "housing probe PT100"
id = "P-19"
certificate = "CAL-2026-0457"
[settings]
block_s = 60
settle_s = 1200
turn_on_tolerance_dph = 1.0
{settings}
''' + "\n".join(runs), encoding="utf-8")
    return CampaignFiles(folder, manifest, tuple(turn_ons), tuple(soaks), sweep, table)
