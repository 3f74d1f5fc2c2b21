"""Tests of hrgtc.fleet.manifest: a fleet from a manifest (CSV, YAML) or the folder convention."""

from __future__ import annotations

import pytest

from hrgtc.core.errors import InputError
from hrgtc.fleet.manifest import load_fleet, read_manifest, scan_root


def _touch(path):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"")
    return path


def test_convention(tmp_path):
    for unit in ("a", "b"):
        for name in ("soak_-20C.parquet", "soak_40C.csv"):
            _touch(tmp_path / unit / "soaks" / name)
        _touch(tmp_path / unit / "drift" / "cool.h5")
    _touch(tmp_path / "a" / "validate" / "warm.parquet")
    _touch(tmp_path / "a" / "soaks" / "notes.txt")  # not a recording: ignored
    fleet = scan_root(tmp_path)
    assert [u.unit for u in fleet] == ["a", "b"]
    assert [p.rsplit("/", 1)[1] for p in fleet[0].soaks] == ["soak_-20C.parquet",
                                                            "soak_40C.csv"]
    assert fleet[0].validate and not fleet[1].validate
    assert [u.unit for u in load_fleet(tmp_path, units=["b"])] == ["b"]
    with pytest.raises(InputError, match=r"\['c'\] are not in the fleet"):
        load_fleet(tmp_path, units=["c"])


def test_csv_and_yaml_manifests(tmp_path):
    (tmp_path / "m.csv").write_text("unit,role,path\nu1,soak,s1.parquet\nu1,drift,/abs/d.csv\n"
                                    "u2, Soak ,x/s.parquet\n")
    fleet = read_manifest(tmp_path / "m.csv")
    assert fleet[0].soaks == (str(tmp_path / "s1.parquet"),)
    assert fleet[0].drifts == ("/abs/d.csv",)
    assert fleet[1].soaks == (str(tmp_path / "x" / "s.parquet"),)
    (tmp_path / "m.yaml").write_text("files:\n  - {unit: u1, role: validate, path: v.csv}\n")
    assert read_manifest(tmp_path / "m.yaml")[0].validate == (str(tmp_path / "v.csv"),)
    (tmp_path / "manifest.csv").write_text("unit,role,path\nz,soak,z.csv\n")
    assert [u.unit for u in load_fleet(tmp_path)] == ["z"]  # a folder's manifest wins


def test_manifest_errors(tmp_path):
    bad_role = tmp_path / "a.csv"
    bad_role.write_text("unit,role,path\nu1,ramp,x.csv\n")
    with pytest.raises(InputError, match="line 2: role 'ramp' is not one of soak, drift"):
        read_manifest(bad_role)
    header = tmp_path / "b.csv"
    header.write_text("serial,kind,file\n")
    with pytest.raises(InputError, match="header must name unit, role and path"):
        read_manifest(header)
    missing = tmp_path / "c.yaml"
    missing.write_text("- {unit: u1, role: soak}\n")
    with pytest.raises(InputError, match="entry 1: missing path"):
        read_manifest(missing)
    with pytest.raises(InputError, match="no unit folders"):
        scan_root(tmp_path)
