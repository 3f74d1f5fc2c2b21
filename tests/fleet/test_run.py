"""Tests of the fleet driver: a real LocalCluster gives the sequential models bit for bit,
a unit with a corrupt file fails alone (with its file), resume skips unchanged units, and the
fleet table and report hold what they promise."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from hrgtc.fleet import calibrate_fleet, load_fleet, report_fleet
from hrgtc.fleet.report import outliers, robust_z
from hrgtc.fleet.results import read_table
from hrgtc.settings.fleet import FleetCluster


def _models(folder: Path) -> dict[str, dict]:
    out = {}
    for path in sorted(folder.glob("*.json")):
        if path.name.endswith(".outcome.json"):
            continue
        data = json.loads(path.read_text())
        data["provenance"].pop("created_utc")
        out[path.name] = data
    return out


def test_local_cluster_equals_sequential_and_a_bad_unit_fails_alone(fleet_root, tmp_path):
    sequential = calibrate_fleet(fleet_root, tmp_path / "seq", cluster=FleetCluster(workers=0))
    parallel = calibrate_fleet(fleet_root, tmp_path / "par", cluster=FleetCluster(workers=2))
    assert parallel.where == "local cluster of 2 workers"
    assert len(parallel.worker_peak_rss_mb) == 2
    for run in (sequential, parallel):
        assert run.counts() == {"ok": 3, "skipped": 0, "failed": 1}
        (bad,) = run.failed
        assert bad.unit == "s5-bad"
        assert bad.error["type"] == "RecordingError"
        assert bad.error["file"].endswith("s5-bad/soaks/soak_-20C.parquet")
    models = _models(tmp_path / "seq")
    assert len(models) == 3
    assert models == _models(tmp_path / "par")  # bit for bit: same functions, same inputs

    rows = {r["unit"]: r for r in read_table(tmp_path / "par" / "fleet.parquet")}
    assert rows["s5-bad"]["status"] == "failed"
    assert rows["s5-bad"]["error_file"].endswith("soak_-20C.parquet")
    good = rows["s5-u0001"]
    assert good["status"] == "ok" and len(good["soak_temperatures_c"]) == 5
    assert good["tcf_ppm_per_c"] == pytest.approx(83.8, rel=0.1)  # 0.3716 / 4432 (Eq. 18)
    assert good["compensated_10s_dph"][0] < good["raw_10s_dph"][0]
    assert good["terms_kept"]

    report, _ = report_fleet(tmp_path / "par", tmp_path / "fleet.html")
    html = report.read_text()
    assert "s5-bad" in html and "RecordingError" in html and "data:image/svg+xml" in html


def test_resume_skips_unchanged_units_and_redoes_changed_ones(fleet_root, tmp_path):
    data = tmp_path / "data"
    shutil.copytree(fleet_root, data)
    first = calibrate_fleet(data, tmp_path / "models", cluster=FleetCluster(workers=0))
    assert first.counts()["failed"] == 1
    with pytest.raises(Exception, match="exist"):
        calibrate_fleet(data, tmp_path / "models", cluster=FleetCluster(workers=0))
    again = calibrate_fleet(data, tmp_path / "models", cluster=FleetCluster(workers=0), resume=True)
    assert again.counts() == {"ok": 0, "skipped": 3, "failed": 1}
    # an outcome written before the long form (the unit's one row, no axes) is redone
    record = tmp_path / "models" / "s5-u0003.outcome.json"
    shutil.copytree(data / "s5-u0002", data / "s5-u0003")
    calibrate_fleet(data, tmp_path / "models", cluster=FleetCluster(workers=0), resume=True)
    stored = json.loads(record.read_text())
    (axis,) = stored.pop("axes")
    record.write_text(json.dumps({**stored, "row": {**stored["row"], **axis, "axis": None}}))
    # repair the bad unit's file and change another unit's drift run
    shutil.copy(fleet_root / "s5-u0000" / "soaks" / "soak_-20C.parquet",
                data / "s5-bad" / "soaks" / "soak_-20C.parquet")
    shutil.copy(fleet_root / "s5-u0002" / "validate" / "warmup_-20C_to_20C.parquet",
                data / "s5-u0001" / "validate" / "warmup_-20C_to_20C.parquet")
    third = calibrate_fleet(data, tmp_path / "models", cluster=FleetCluster(workers=0), resume=True)
    status = {o.unit: o.status for o in third.outcomes}
    assert status == {"s5-bad": "ok", "s5-u0000": "skipped", "s5-u0001": "ok",
                      "s5-u0002": "skipped", "s5-u0003": "ok"}
    rows = read_table(tmp_path / "models" / "fleet.parquet")
    assert [(r["unit"], r["axis"]) for r in rows] == [(u, "") for u in sorted(status)]
    assert [u.unit for u in load_fleet(data)] == sorted(status)


def test_robust_z_flags_the_odd_unit():
    rows = [{"unit": f"u{k}", "status": "ok", "relative_coefficients": [1.0 + 0.01 * k, 2.0],
             "median_improvement_10s": 5.0 + 0.1 * k} for k in range(9)]
    rows.append({"unit": "odd", "status": "ok", "relative_coefficients": [1.5, 2.0],
                 "median_improvement_10s": 5.2})
    z = robust_z([r["relative_coefficients"][0] for r in rows])
    assert abs(z[-1]) > 3.5 and max(abs(z[:-1])) < 3.5
    assert [(f["unit"], f["quantity"]) for f in outliers(rows)] == [("odd", "b1")]


def test_an_existing_cluster_from_the_environment_runs_the_same_code(fleet_root, tmp_path,
                                                                     monkeypatch):
    from distributed import LocalCluster

    sequential = calibrate_fleet(fleet_root, tmp_path / "seq", cluster=FleetCluster(workers=0))
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None, host="127.0.0.1") as cluster:
        monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", cluster.scheduler_address)
        remote = calibrate_fleet(fleet_root, tmp_path / "remote")
    assert remote.where == cluster.scheduler_address
    assert remote.counts() == sequential.counts()
    assert _models(tmp_path / "remote") == _models(tmp_path / "seq")
