"""Simulated chamber campaigns on disk for calibration tests (reduced sample rate)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)
RATE_HZ = 5.0  # the physics and the 10 s bias stability do not depend on the rate


@dataclass(frozen=True)
class Campaign:
    soaks: list[Path]
    cooldown: Path
    warmup: Path


def make_campaign(folder: Path, unit: str, sample_rate_hz: float = RATE_HZ, hours: float = 5.0,
                  seed: int = 1) -> Campaign:
    """Seven soaks, a cool-down (training) and a warm-up with another seed (validation)."""
    soaks = simulate_files([profiles.soak(sp, hours) for sp in SETPOINTS_C], folder / "soaks",
                           "parquet", unit=unit, sample_rate_hz=sample_rate_hz, seed=seed)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], folder / "cool", "parquet",
                          unit=unit, sample_rate_hz=sample_rate_hz, seed=seed + 1)
    warm = simulate_files([profiles.warmup(-20.0, 20.0, 5.0)], folder / "warm", "parquet",
                          unit=unit, sample_rate_hz=sample_rate_hz, seed=seed + 2)
    return Campaign([Path(w.path) for w in soaks], Path(cool[0].path), Path(warm[0].path))
