"""Plausible-looking corruptions of model files, each with its expected outcome (issue 21).

The model side of :mod:`corruptions`: absurd but finite coefficients (with the hash line
removed, as the README allows after a deliberate edit), a model trained on a rate in
another unit, a model of another axis set or another unit, a sensor-thermometer model on a
frequency recording, reversed or missing ranges, damaged bytes, and edits that leave the
numbers valid. Each :class:`~corruptions.Case` is run with the undamaged recording of its
``axes`` through ``compensate``, ``evaluate``, ``export-c`` (C and parameter file) and
``report``.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np

from hrgtc import drift
from hrgtc.model import AxisModel, Model, save_model
from hrgtc.model_schema import derived_coefficients
from hrgtc.recording import ReadOptions, Recording

from corruptions import CORRECT, Case, Expect, Material, error
from synthetic import THERMOMETER, ramp_run

HASH_KEY = "parameters_sha256"


def json_edit(change: Callable[[dict], None], keep_hash: bool = False) -> Callable:
    """The single-axis model file with ``change`` applied to its JSON."""
    def make(material: Material, folder: Path) -> Path:
        data = json.loads(material.model_path.read_text())
        change(data)
        if not keep_hash:
            data.pop(HASH_KEY, None)
        path = folder / "case.json"
        path.write_text(json.dumps(data, indent=1))
        return path
    return make


def absurd(term: str, value: float) -> Callable[[dict], None]:
    """One drift coefficient (or the intercept) set to ``value``, scaled ones kept consistent."""
    def change(data: dict) -> None:
        model = data["drift"]
        if term == "intercept":
            model["intercept_dph"] = value
            return
        i = model["selected"].index(term)
        model["scaled_coefficients"][i] = value
        model["coefficients"] = derived_coefficients(model)
    return change


def text_edit(change: Callable[[str], str]) -> Callable:
    """The single-axis model file (hash removed) with ``change`` applied to its text."""
    def make(material: Material, folder: Path) -> Path:
        data = json.loads(material.model_path.read_text())
        data.pop(HASH_KEY, None)
        path = folder / "case.json"
        path.write_text(change(json.dumps(data, indent=1)))
        return path
    return make


def duplicated_key(key: str, inside: str | None) -> Callable[[str], str]:
    """A second ``key`` (another value) written before the first: json keeps the last."""
    def change(text: str) -> str:
        data = json.loads(text)
        value = (data[inside] if inside else data)[key]
        other = json.dumps(value + "-other" if isinstance(value, str) else value * 2 + 1)
        anchor = f'"{inside}": {{' if inside else "{"
        at = text.index(anchor) + len(anchor)
        return f'{text[:at]}\n "{key}": {other},{text[at:]}'
    return change


def unknown_key(key: str, inside: str | None) -> Callable[[dict], None]:
    def change(data: dict) -> None:
        (data[inside] if inside else data)[key] = 1.0
    return change


def reversed_range(path: str) -> Callable[[dict], None]:
    def change(data: dict) -> None:
        *parents, last = path.split(".")
        node = data
        for key in parents:
            node = node[key]
        node[last] = list(reversed(node[last]))
    return change


def deleted(path: str) -> Callable[[dict], None]:
    def change(data: dict) -> None:
        *parents, last = path.split(".")
        node = data
        for key in parents:
            node = node[key]
        del node[last]
    return change


def shifted_unit(hz: float) -> Callable[[dict], None]:
    """Another unit's model: its resonator runs ``hz`` higher at every temperature."""
    def change(data: dict) -> None:
        therm = data["thermometer"]
        therm["coefficients"][0] += hz
        therm["scaled_coefficients"][0] += hz
        data["drift"]["settings"]["reference_freq_hz"] += hz
    return change


def byte_damage(how: str, where: float) -> Callable:
    def make(material: Material, folder: Path) -> Path:
        raw = bytearray(material.model_path.read_bytes())
        at = int(where * (len(raw) - 1))
        raw = raw[:at] if how == "truncate" else raw
        if how == "flip":
            raw[at] ^= 0x04
        path = folder / "case.json"
        path.write_bytes(bytes(raw))
        return path
    return make


def trained_in(factor: float) -> Callable:
    """A model whose drift was fitted on the rate times ``factor`` (the logger's other unit)."""
    def make(material: Material, folder: Path) -> Path:
        run = ramp_run(seed=11, hours=3.0)
        columns = {k: run[k] * (factor if k in ("rate_dph", "bias_dph") else 1.0)
                   for k in run.names}
        meta = dataclasses.replace(run.metadata,
                                   input_rate_dph=run.metadata.input_rate_dph * factor)
        from hrgtc.drift.training import TrainingStatistics

        trained = Recording(columns, meta)
        # what calibrate writes: the model carries the statistics of its training data
        model = Model.single(
            AxisModel(thermometer=THERMOMETER, drift=drift.fit([trained], THERMOMETER),
                training=TrainingStatistics.from_runs([trained])), unit="FZ-1")
        return save_model(model, folder / "case.json", force=True)
    return make


def instrument(axes: str) -> Callable:
    def make(material: Material, folder: Path) -> Path:
        model = Model({a: material.model.axis for a in axes}, unit="FZ-3")
        return save_model(model, folder / "case.json", force=True)
    return make


def sensor_model(material: Material, folder: Path) -> Path:
    """A sensor-thermometer model (calibrated on the recording's temperature_c)."""
    from hrgtc.pipeline.calibration import calibrate

    result = calibrate([], [material.run_path("1")], read_options=ReadOptions(thermometer="sensor"))
    return save_model(result.model, folder / "case.json", force=True)


def model_cases() -> list[Case]:
    """Every model case (≥ 70), in a fixed order."""
    cases: list[Case] = []

    def add(name: str, family: str, make: Callable, expect: dict[str, Expect],
            owner: str = "main", axes: str = "1") -> None:
        cases.append(Case(name, family, "model", make, expect, owner, axes))

    for term in ("intercept", "f", "f^2", "df"):
        for value in (1e300, -1e300, 1e12, 1e8):
            add(f"{term} = {value:g} (hash removed)", "absurd coefficient",
                json_edit(absurd(term, value)),
                {"*": error("intercept" if term == "intercept" else term)}, owner="relmodel")
    add("intercept = 1e308 (hash removed)", "absurd coefficient",
        json_edit(absurd("intercept", 1e308)), {"*": error("intercept")}, owner="relmodel")
    for factor, unit in ((1 / 3600.0, "°/s"), (np.pi / 180, "rad/s"), (1e-3, "k°/h"),
                         (3600.0, "°/h·3600")):
        add(f"trained on a rate in {unit} (x{factor:.4g})", "model of another rate unit",
            trained_in(factor), {"*": error("rate_dph"), "export-c": CORRECT,
                                 "export-params": CORRECT}, owner="relmodel")
    for axes, run_axes, named in (("xyz", "1", "axis"), ("xy", "3", "z"), ("xyzw", "3", "w")):
        add(f"model of axes {axes} on a {run_axes}-axis recording", "model of another axis set",
            instrument(axes), {"*": error(named), "export-c": CORRECT, "export-params": CORRECT},
            owner="relmodel" if axes != "xyz" else "main", axes=run_axes)
    add("single-axis model on a 3-axis recording", "model of another axis set",
        lambda m, f: m.model_path, {"*": error("axes"), "export-c": CORRECT,
                                    "export-params": CORRECT}, owner="relmodel", axes="3")
    add("sensor-thermometer model on a frequency recording", "sensor model", sensor_model,
        {"*": error("sensor"), "export-c": CORRECT, "export-params": CORRECT}, owner="relmodel")
    for hz in (300.0, -500.0):
        add(f"another unit's model ({hz:+g} Hz)", "model of another unit",
            json_edit(shifted_unit(hz)), {"*": error("freq_hz"), "export-c": CORRECT,
                                          "export-params": CORRECT})
    for path in ("drift.ranges.f", "drift.ranges.df", "thermometer.temperature_range_c"):
        add(f"{path} reversed", "reversed range", json_edit(reversed_range(path)),
            {"*": error(path)})
    for path in ("drift.ranges.df", "drift.settings.reference_freq_hz", "thermometer.scale_c",
                 "drift.selected"):
        add(f"{path} deleted", "missing field", json_edit(deleted(path)),
            {"*": error(path.rsplit(".", 1)[0])})
    for term in ("f", "df"):
        add(f"coefficient {term} edited, hash kept", "edited", json_edit(
            absurd(term, 2.0), keep_hash=True), {"*": error(HASH_KEY)})
    add("provenance removed (hash kept)", "edited",
        json_edit(lambda d: d.pop("provenance", None), keep_hash=True), {"*": CORRECT})
    add("unit renamed (hash removed)", "edited",
        json_edit(lambda d: d.update(unit="FZ-1 renamed")), {"*": CORRECT,
                                                            "export-c": Expect("correct",
                                                                               compare=False)})
    # issue 27's audit: keys another JSON reader reads otherwise, or that nothing reads
    for key, inside in (("unit", None), ("intercept_dph", "drift")):
        add(f"duplicate key {key!r}" + (f" in {inside}" if inside else ""), "json keys",
            text_edit(duplicated_key(key, inside)), {"*": error(key, "twice")})
    for key, inside in (("units", None), ("intercept", "drift"), ("scale", "thermometer")):
        add(f"unknown key {key!r}" + (f" in {inside}" if inside else ""), "json keys",
            json_edit(unknown_key(key, inside)), {"*": error(key)})
    for section in ("drift", "thermometer"):
        add(f"{section} section missing", "missing field", json_edit(deleted(section)),
            {"*": error(section)})
    for i in range(20):
        add(f"truncated at {i / 20:.0%}", "damaged bytes", byte_damage("truncate", i / 20),
            {"*": error("model")})
        add(f"bit flipped at {(i + 0.5) / 20:.1%}", "damaged bytes",
            byte_damage("flip", (i + 0.5) / 20), {"*": Expect("error_or_same")})
    return cases
