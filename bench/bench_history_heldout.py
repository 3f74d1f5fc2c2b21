"""Held-out heating, fast cooling and a cycle on a unit with a true play memory (issue 29).

For each seed: ``unit-play`` (:mod:`hrgtc.simulate.units`; a play operator of width 2 °C on
the resonator temperature, a law from outside the candidate terms) with its play's state at
power-on drawn uniformly in ±w/2 for every run (a history the model does not know);
seven 5 h soaks (the thermometer; their transients are drift training runs, the default)
and a cool-down 20 -> -20 °C and a warm-up -20 -> 20 °C at 1 °C/min (the drift training
runs); held out: a heating run -10 -> 40 °C at 0.5 °C/min, a fast cooling 40 -> -20 °C at
2 °C/min and the temperature cycle of ``bench_heldout.py``. Each run's figure is its
compensated 10 s bias stability over its oracle, the same run's gyro noise alone (the true
bias removed), as in ``bench_heldout.py``; heating and cooling stretches also apart.

One JSON line per held-out run kind with the median over seeds and its 95 % bootstrap
interval (seeds resampled, 2000 draws); with ``--terms=...`` (candidates beyond the
default, e.g. ``--terms=f,f^2,f^3,df,f*df,g,play``) also the paired line: the median over
seeds of (ratio with the terms) / (ratio with the default candidates), with its interval.

With ``--history``: :func:`hrgtc.pipeline.terms.add_history`, the estimator's history
step: ``play`` added on top of today's selection, its width learned per seed from a grid
(``--widths=1,2,4``; default :data:`hrgtc.drift.variables.play.WIDTHS_C`) by the fits'
leave-one-run-out score, then ``gsat``, each kept only where that score beats the model
without it (the rows say ``play_width_c``, ``kept``, ``added`` and both scores); the
paired line compares it with today's model. With
``--train-cycle`` the training runs also hold a cycle that turns round
(:data:`TRAIN_CYCLE`), which shows the play's width whatever the history.

Usage: ``python bench/bench_history_heldout.py --seeds=20 [--terms=... | --history]``.
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_heldout import CYCLE, SETPOINTS_C, _calibrate_keywords, _measure

RUNS = ("heating", "fast_cooling", "cycle")
#: A training run that turns round (``--train-cycle``): 20 -> 0 -> 30 -> 20 °C at 1 °C/min.
TRAIN_CYCLE = {"name": "train_cycle", "start_c": 20.0, "segments": [
    {"setpoint_c": 0.0, "ramp_c_per_min": 1.0}, {"setpoint_c": 0.0, "hold_h": 1.0},
    {"setpoint_c": 30.0, "ramp_c_per_min": 1.0}, {"setpoint_c": 30.0, "hold_h": 1.0},
    {"setpoint_c": 20.0, "ramp_c_per_min": 1.0}, {"setpoint_c": 20.0, "hold_h": 0.5}]}
TARGET = 1.15


#: Run keys of :func:`_campaign`: the held-out runs, and every run (soaks 10-16).
HELDOUT_KEYS = (3, 4, 5)
ALL_KEYS = (1, 2, 3, 4, 5, 6, *range(10, 17))


def _unit(seed: int, k: int, known: bool = False):
    """unit-play with the play's power-on state drawn for run ``k`` of ``seed`` (``known``:
    at the run's first temperature, where the model's power-on rule puts it)."""
    from hrgtc.simulate import units

    base = units.get("unit-play")
    half = 0.5 * base.bias_law.play_width_c
    offset = float(np.random.default_rng([seed, k]).uniform(-half, half))
    return replace(base, bias_law=replace(base.bias_law,
                                          play_initial_offset_c=0.0 if known else offset))


def _campaign(seed: int, folder: Path, fs: float, hours: float,
              train_cycle: bool = False, known: tuple[int, ...] = ()) -> dict:
    """The seed's files: soaks, training runs (with :data:`TRAIN_CYCLE` if asked), held-out
    runs; the runs whose key is in ``known`` start with the play's state known (the same
    noise: a paired comparison)."""
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles
    from hrgtc.simulate.profiles import from_mapping

    def sim(profile, name, k):
        return Path(simulate_files([profile], folder / f"{seed}-{name}", "parquet",
                                   unit=_unit(seed, k, k in known), sample_rate_hz=fs,
                                   seed=100 * seed + k)[0].path)

    soaks = [sim(profiles.soak(sp, hours), f"soak{k}", 10 + k)
             for k, sp in enumerate(SETPOINTS_C)]
    training = [sim(profiles.cooldown(20.0, -20.0, 5.0), "cool", 1),
                sim(profiles.warmup(-20.0, 20.0, 5.0), "warm", 2)]
    if train_cycle:
        training.append(sim(from_mapping(TRAIN_CYCLE), "train_cycle", 6))
    return {
        "soaks": soaks,
        "training": training,
        "heldout": {
            "heating": sim(profiles.warmup(-10.0, 40.0, 5.0, ramp_c_per_min=0.5), "heat", 3),
            "fast_cooling": sim(profiles.cooldown(40.0, -20.0, 4.0, ramp_c_per_min=2.0),
                                "fastcool", 4),
            "cycle": sim(from_mapping(CYCLE), "cycle", 5),
        },
    }


def _fit(files: dict, options: dict):
    from hrgtc.pipeline.calibration import calibrate

    return calibrate(files["soaks"], files["training"], **_calibrate_keywords(options)).model


def _loro(model) -> float:
    """The fit's leave-one-run-out score (RMS over training runs of the held-out 10 s
    stability of the window residuals, :class:`hrgtc.drift.cross_validation.CrossValidation`)."""
    validation = model.drift.cross_validation
    return float("inf") if validation is None else float(validation.score_dph)


def _rows(model, files: dict, fs: float, seed: int, **extra) -> list[dict]:
    rows = []
    for name, path in files["heldout"].items():
        row = {"seed": seed, "run": name, **_measure(path, model, fs)}
        row["ratio"] = row["comp"] / row["floor"]
        row["terms"] = list(model.drift.selected)
        rows.append({**row, **extra})
    return rows


def _fit_and_measure(files: dict, options: dict, fs: float, seed: int) -> list[dict]:
    return _rows(_fit(files, options), files, fs, seed)


def _history_fits(files: dict, widths: tuple[float, ...], fs: float, seed: int
                  ) -> tuple[list[dict], list[dict]]:
    """Rows of today's model and of the model with the history terms added on top of its
    selection, each kept only where it wins leave-one-run-out
    (:func:`hrgtc.pipeline.terms.add_history`, the play's width learned from ``widths``)."""
    from hrgtc.pipeline.terms import add_history

    choice = add_history(lambda options: _fit(files, options), widths)
    extra = {"play_width_c": choice.play_width_c, "kept": bool(choice.added),
             "added": list(choice.added), "loro_today": round(choice.scores["base"], 4),
             "loro_history": round(_loro(choice.model), 4)}
    return (_rows(choice.base, files, fs, seed),
            _rows(choice.model, files, fs, seed, **extra))


def _interval(values: list[float], rng: np.random.Generator, draws: int = 2000
              ) -> tuple[float, float]:
    """95 % percentile bootstrap interval of the median (values resampled)."""
    data = np.asarray(values, dtype=np.float64)
    picks = rng.integers(0, data.size, size=(draws, data.size))
    medians = np.median(data[picks], axis=1)
    return float(np.percentile(medians, 2.5)), float(np.percentile(medians, 97.5))


def _summary(rows: list[dict], label: str, seconds: float) -> list[dict]:
    rng = np.random.default_rng(29)
    out = []
    for run in (*RUNS, "all"):
        sel = [r for r in rows if run == "all" or r["run"] == run]
        ratios = [r["ratio"] for r in sel]
        low, high = _interval(ratios, rng)
        line = {"name": f"history_heldout_{label}_{run}", "n": len(sel),
                "seconds": round(seconds, 1), "rate": round(len(sel) / seconds, 4),
                "ratio_median": round(statistics.median(ratios), 3),
                "ratio_ci95": [round(low, 3), round(high, 3)],
                "ratio_worst": round(max(ratios), 3)}
        for kind in ("heating", "cooling"):
            values = [r[f"{kind}_ratio"] for r in sel if f"{kind}_ratio" in r]
            if values:
                low, high = _interval(values, rng)
                line[f"{kind}_ratio_median"] = round(statistics.median(values), 3)
                line[f"{kind}_ratio_ci95"] = [round(low, 3), round(high, 3)]
                line[f"{kind}_ratio_worst"] = round(max(values), 3)
        worst = max([line["ratio_worst"], line.get("heating_ratio_worst", 0.0),
                     line.get("cooling_ratio_worst", 0.0)])
        line["within_target"] = worst <= TARGET
        terms: dict[str, int] = {}
        for r in sel:
            for term in r["terms"]:
                terms[term] = terms.get(term, 0) + 1
        line["terms_selected"] = dict(sorted(terms.items(), key=lambda kv: -kv[1]))
        if any("kept" in r for r in sel):
            line["history_kept"] = sum(bool(r["kept"]) for r in sel)
            widths = [r["play_width_c"] for r in sel if r["kept"]]
            line["play_width_c_kept"] = sorted(set(widths))
        out.append(line)
    return out


def _paired(before: list[dict], after: list[dict], label: str) -> list[dict]:
    """Median over seeds of after/before per run kind, with its bootstrap interval."""
    rng = np.random.default_rng(290)
    key = {(r["seed"], r["run"]): r["ratio"] for r in before}
    out = []
    for run in (*RUNS, "all"):
        pairs = [r["ratio"] / key[(r["seed"], r["run"])] for r in after
                 if run == "all" or r["run"] == run]
        low, high = _interval(pairs, rng)
        out.append({"name": f"history_paired_{label}_{run}", "n": len(pairs),
                    "after_over_before_median": round(statistics.median(pairs), 3),
                    "after_over_before_ci95": [round(low, 3), round(high, 3)],
                    "better_in": sum(p < 1.0 for p in pairs)})
    return out


def history(seeds: tuple[int, ...], widths: tuple[float, ...],
            fs: float = 1.0, hours: float = 5.0, train_cycle: bool = False,
            ) -> dict[str, tuple[list[dict], float]]:
    """Rows of today's model and of the history terms' (see :func:`_history_fits`)."""
    rows: dict[str, list[dict]] = {"default": [], "history": []}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            files = _campaign(seed, Path(tmp), fs, hours, train_cycle)
            today, after = _history_fits(files, widths, fs, seed)
            rows["default"].extend(today)
            rows["history"].extend(after)
    seconds = time.perf_counter() - start
    return {label: (values, seconds) for label, values in rows.items()}


def heldout(seeds: tuple[int, ...], option_sets: dict[str, dict], fs: float = 1.0,
            hours: float = 5.0) -> dict[str, tuple[list[dict], float]]:
    """Rows per label (one fit per seed and label, on the same files) and their seconds."""
    rows: dict[str, list[dict]] = {label: [] for label in option_sets}
    seconds = dict.fromkeys(option_sets, 0.0)
    with tempfile.TemporaryDirectory() as tmp:
        for seed in seeds:
            files = _campaign(seed, Path(tmp), fs, hours)
            for label, options in option_sets.items():
                start = time.perf_counter()
                rows[label].extend(_fit_and_measure(files, options, fs, seed))
                seconds[label] += time.perf_counter() - start
    return {label: (rows[label], seconds[label]) for label in option_sets}


def run(quick: bool = False) -> list[dict]:
    result = heldout((1, 2) if quick else (1, 2, 3, 4, 5), {"default": {}})
    rows, seconds = result["default"]
    return _summary(rows, "default", seconds)


if __name__ == "__main__":
    count = next((int(a.split("=", 1)[1]) for a in sys.argv if a.startswith("--seeds=")), 20)
    option_sets: dict[str, dict] = {"default": {}}
    for arg in sys.argv:
        if arg.startswith("--terms="):
            terms = tuple(arg.split("=", 1)[1].split(","))
            option_sets["terms_" + "_".join(terms).replace("*", "").replace("^", "")] = {
                "terms": terms}
    if "--history" in sys.argv:  # today's candidates + gsat + play, the width learned
        from hrgtc.drift.variables.play import WIDTHS_C

        widths = next((tuple(float(w) for w in a.split("=", 1)[1].split(","))
                       for a in sys.argv if a.startswith("--widths=")), WIDTHS_C)
        results = history(tuple(range(1, count + 1)), widths,
                          train_cycle="--train-cycle" in sys.argv)
    else:
        results = heldout(tuple(range(1, count + 1)), option_sets)
    for label, (rows, seconds) in results.items():
        for line in _summary(rows, label, seconds):
            print(json.dumps(line), flush=True)
        if label != "default":
            for line in _paired(results["default"][0], rows, label):
                print(json.dumps(line), flush=True)
    if "-v" in sys.argv:
        for label, (rows, _) in results.items():
            for row in rows:
                print(json.dumps({"label": label, **{k: (round(v, 3) if isinstance(v, float)
                                                         else v) for k, v in row.items()}}),
                      file=sys.stderr)
