"""Settings of the fleet stage: the simulated population and the demo's campaign."""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: Chamber set-points of Table 1 of [1]. [°C]
#:
#: [1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)
#: File formats of simulated runs.
FILE_FORMATS = ("parquet", "csv", "h5")


@dataclass(frozen=True)
class FleetSimulation:
    """The population ``hrgtc fleet simulate`` writes (:func:`hrgtc.fleet.simulate_fleet`)."""

    units: int = setting(32, "Number of units.", min=1)
    seed: int = setting(1, "Seed of the population.", min=0)
    sample_rate_hz: float = setting(10.0, "Sample rate.", unit="Hz",
                                    cli="--sample-rate-hz --rate-hz")
    soak_hours: float = setting(5.0, "Length of each soak.", unit="h")
    ramp_hours: float = setting(5.0, "Length of the cool-down and warm-up.", unit="h")
    setpoints_c: tuple[float, ...] = setting(
        SETPOINTS_C, "Soak set-points, comma separated.", unit="°C", cli="--setpoints")
    file_format: str = setting("parquet", "File format.", cli="--format",
                               choices=FILE_FORMATS)
    axes: int = setting(1, "Axes per unit: 1, or 2-3 for instruments whose resonators (x, y, "
                        "z), each drawn as a unit is, share one housing.", min=1, max=3)


@dataclass(frozen=True)
class FleetCluster:
    """Where a fleet command runs its tasks, one per unit (:func:`hrgtc.fleet.run.run_tasks`)."""

    scheduler: str | None = setting(
        None, "Address of an existing Dask scheduler (default: DASK_SCHEDULER_ADDRESS, else a "
        "local cluster on this machine).", metavar="tcp://HOST:8786", panel="Cluster")
    workers: int | None = setting(
        None, "Worker processes of the local cluster; 0 runs the units here, one after the "
        "other.", default_text="one per core", panel="Cluster", min=0)


@dataclass(frozen=True)
class FleetCalibration:
    """Which units ``hrgtc fleet calibrate`` calibrates, and with what prior
    (:func:`hrgtc.fleet.calibrate_fleet`)."""

    units: tuple[str, ...] = setting(
        (), "Only this unit (repeat for more); none: every unit.", cli="--unit",
        multiple=True, metavar="UNIT")
    resume: bool = setting(
        False, "Skip units whose model exists and whose inputs are unchanged (SHA-256).")
    prior: str | None = setting(
        None, "Population prior (hrgtc fleet prior): fit each thermometer with it.",
        metavar="PRIOR.json", default_text="none")


@dataclass(frozen=True)
class FleetEvaluation:
    """What ``hrgtc fleet evaluate`` computes (:func:`hrgtc.fleet.evaluate_fleet`)."""

    allan: bool = setting(True, "Also compute the Allan noise terms.", cli="--allan/--no-allan")


@dataclass(frozen=True)
class DemoSettings:
    """Sample rate and durations of the simulated campaign of ``hrgtc demo``."""

    sample_rate_hz: float = 200.0  # Section 3 of [1]: 200 Hz
    soak_hours: float = 5.0  # "4-5 h" per soak
    ramp_hours: float = 5.0
    seed: int = setting(2012, "Seed of the simulated campaign.")
    #: Sample rate of the three-axis part (None: skip it). [Hz]
    instrument_rate_hz: float | None = 10.0
    #: Sample rate of the thermal-history part, unit-play (None: skip it); the same in
    #: ``quick``, so that its figures are those of ``make demo``. [Hz]
    history_rate_hz: float | None = 1.0

    @classmethod
    def quick(cls, seed: int | None = None) -> DemoSettings:
        """Lower rate and shorter soaks (settled-value extrapolation does the rest)."""
        return cls(sample_rate_hz=5.0, soak_hours=3.0, ramp_hours=5.0, instrument_rate_hz=1.0,
                   seed=cls.seed if seed is None else seed)
