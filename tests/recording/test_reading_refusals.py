"""What the reader refuses, and with which message (issue 21, the reading side).

Each test builds a valid recording, damages it the way a real file is damaged (an
axis column dropped or stored as a matrix, CR-only line ends, a trailing
delimiter, spaces between values, a duplicated or swapped header) and checks that
reading it is an error naming the file and the column and saying the fix, or that
the file reads back equal to the undamaged one. On the main branch before this work
each of these read silently wrong or failed with a misleading message.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from hrgtc.core.errors import RecordingError
from hrgtc.recording import Recording, axis_names, read, write

from synthetic import ramp_run

COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c")


@pytest.fixture(scope="module")
def run() -> Recording:
    full = ramp_run(seed=3, start_c=10.0, end_c=5.0, hours=0.05)
    return Recording({k: full[k] for k in COLUMNS}, full.metadata)


@pytest.fixture(scope="module")
def three_axis(run) -> Recording:
    columns = {"time_s": run["time_s"], "chamber_c": run["chamber_c"],
               "temperature_c": run["chamber_c"] + 0.5}
    for i, axis in enumerate("xyz"):
        columns[f"freq_hz_{axis}"] = run["freq_hz"] + i
        columns[f"rate_dph_{axis}"] = run["rate_dph"] - i
    return Recording(columns, run.metadata)


def _drop_csv_column(text: str, name: str) -> str:
    lines = text.split("\n")
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    j = lines[header].split(",").index(name)
    return "\n".join(",".join(f for k, f in enumerate(line.split(",")) if k != j)
                     if i >= header and line else line for i, line in enumerate(lines))


# -- axis sets ------------------------------------------------------------------------------
def test_a_csv_axis_without_its_rate_column_is_an_error_naming_the_column(three_axis, tmp_path):
    text = write(three_axis, tmp_path / "imu.csv").read_text()
    path = tmp_path / "no_rate_z.csv"
    path.write_text(_drop_csv_column(text, "rate_dph_z"))
    with pytest.raises(RecordingError, match=r"no_rate_z.csv: column 'freq_hz_z' belongs to "
                       r"axis 'z', which has no 'rate_dph_z'.*--col rate_dph_z="):
        read(path)


def test_a_temperature_column_of_a_missing_axis_is_an_error_too(three_axis, tmp_path):
    columns = {k: three_axis[k] for k in three_axis.names
               if not k.endswith("_z")} | {"temperature_c_z": three_axis["chamber_c"]}
    path = write(Recording(columns, three_axis.metadata), tmp_path / "t.parquet")
    with pytest.raises(RecordingError, match="column 'temperature_c_z' belongs to axis 'z'"):
        read(path)


def test_one_shared_temperature_column_stays_legal(three_axis, tmp_path):
    back = read(write(three_axis, tmp_path / "imu.h5"))
    assert axis_names(back.names) == ("x", "y", "z")
    np.testing.assert_array_equal(back["temperature_c"], three_axis["temperature_c"])


def test_a_single_axis_file_may_keep_a_column_that_only_looks_per_axis(run, tmp_path):
    columns = {**{k: run[k] for k in run.names}, "temperature_c_ambient": run["chamber_c"]}
    back = read(write(Recording(columns, run.metadata), tmp_path / "a.csv"))
    assert axis_names(back.names) == () and "temperature_c_ambient" in back.names


def test_a_plain_rate_beside_per_axis_rates_is_ambiguous(run, tmp_path):
    """Issue 27's audit: a single-axis file with a stray rate_dph_x became a one-axis
    instrument 'x', its rate_dph ignored."""
    columns = {**{k: run[k] for k in run.names}, "rate_dph_x": run["rate_dph"]}
    path = write(Recording(columns, run.metadata), tmp_path / "stray.csv")
    with pytest.raises(RecordingError, match=r"stray.csv: column 'rate_dph' has no axis, beside "
                       r"the per-axis rate column\(s\) \['rate_dph_x'\] of axes \['x'\]: hrgtc "
                       r"cannot tell whether the file is one gyro's"):
        read(path)


def test_a_plain_frequency_beside_per_axis_ones_is_ambiguous(three_axis, tmp_path):
    """Issue 27's audit: a 3-axis file with an extra plain freq_hz was read, the plain
    column taken for a temperature (4417.9 °C) by the sensor thermometer."""
    columns = {**{k: three_axis[k] for k in three_axis.names},
               "freq_hz": three_axis["freq_hz_x"]}
    path = write(Recording(columns, three_axis.metadata), tmp_path / "extra.parquet")
    for thermometer in ("resonator", "sensor"):
        with pytest.raises(RecordingError, match=r"extra.parquet: column 'freq_hz' has no axis.*"
                           r"whose resonator it is; remove or rename 'freq_hz'"):
            read(path, thermometer=thermometer)


@pytest.mark.parametrize("pad", ["", "   ", "\0\0"])
def test_hdf5_numbers_as_padded_byte_strings_are_read(run, tmp_path, pad):
    """Issue 27's audit: fixed-length byte strings padded with spaces (as MATLAB and
    Fortran write them) got "'4417.677   ' is not a number"."""
    path = write(run, tmp_path / "bytes.h5")
    with h5py.File(path, "a") as handle:
        values = handle["recording/freq_hz"][:]
        del handle["recording/freq_hz"]
        handle["recording/freq_hz"] = np.array([(repr(float(v)) + pad).encode()
                                                for v in values], dtype="S32")
    np.testing.assert_array_equal(read(path)["freq_hz"], run["freq_hz"])


@pytest.mark.parametrize(("stray", "what"), [
    ("\r", r"a carriage return \(\\r\) inside the line at character 4 splits it"),
    ('"', r'a quote \(\"\) without its closing one at character 4 runs into the lines')])
def test_a_stray_cr_or_quote_inside_a_csv_row_is_named_at_its_line(run, tmp_path, stray, what):
    """Issue 27's audit: "line ? (row ?): expected 5 fields, got ?"."""
    lines = write(run, tmp_path / "ok.csv").read_text().split("\n")
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    lines[header + 1 + 100] = lines[header + 1 + 100].replace(",", "," + stray, 1)
    path = tmp_path / "stray.csv"
    path.write_bytes("\n".join(lines).encode())
    with pytest.raises(RecordingError, match=rf"stray.csv: line {header + 102} \(row 100\): "
                                             rf"expected 4 fields; {what}"):
        read(path)


def test_an_upper_case_header_reads_as_the_contract_names(three_axis, tmp_path):
    """Issue 27's audit: RATE_DPH_X, ... was "single-axis (freq_hz, rate_dph)" against a
    3-axis model, and "required column(s) 'time_s' ... missing" for info."""
    from hrgtc.compensate.multi_axis import recording_axes

    lines = write(three_axis, tmp_path / "imu.csv").read_text().split("\n")
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    lines[header] = lines[header].upper()
    path = tmp_path / "upper.csv"
    path.write_text("\n".join(lines))
    back = read(path)
    assert sorted(back.names) == sorted(three_axis.names)
    np.testing.assert_array_equal(back["rate_dph_z"], three_axis["rate_dph_z"])
    assert recording_axes(path) == ("x", "y", "z")


@pytest.mark.parametrize("shape", ["n3", "n1", "scalar"])
def test_an_hdf5_column_that_is_not_1d_is_an_error_naming_it(three_axis, run, tmp_path, shape):
    source = three_axis if shape == "n3" else run
    name = "rate_dph_x" if shape == "n3" else "rate_dph"
    path = write(source, tmp_path / "r.h5")
    with h5py.File(path, "a") as handle:
        group = handle["recording"]
        values = group[name][:]
        del group[name]
        group[name] = {"n3": np.stack([values] * 3, axis=1), "n1": values[:, None],
                       "scalar": np.float64(1.0)}[shape]
    want = {"n3": r"is of shape \(1800, 3\)", "n1": r"is of shape \(1800, 1\)",
            "scalar": r"is a scalar \(shape \(\)\)"}[shape]
    with pytest.raises(RecordingError, match=rf"r.h5: dataset '{name}' {want}, not a 1-D column"):
        read(path)


def test_a_column_mapped_to_a_matrix_dataset_names_its_shape(run, tmp_path):
    path = write(run, tmp_path / "r.h5")
    with h5py.File(path, "a") as handle:
        handle["recording"]["gyro"] = np.zeros((len(run), 3))
    with pytest.raises(RecordingError, match=r"dataset 'gyro' \(given for rate_dph\) has shape "
                       r"\(1800, 3\)"):
        read(path, columns={"rate_dph": "gyro"})


def test_an_hdf5_compound_table_is_named_as_such(run, tmp_path):
    table = np.zeros(len(run), dtype=[(k, "f8") for k in COLUMNS[:3]])
    for k in COLUMNS[:3]:
        table[k] = run[k]
    path = tmp_path / "compound.h5"
    with h5py.File(path, "w") as handle:
        handle["recording"] = table
    with pytest.raises(RecordingError, match=r"compound.h5: dataset 'recording' is a compound "
                       r"table \(fields time_s, freq_hz, rate_dph\)"):
        read(path)


# -- CSV layouts ------------------------------------------------------------------------------
def test_cr_only_line_ends_are_named_with_the_fix(run, tmp_path):
    path = tmp_path / "mac.csv"
    path.write_bytes(write(run, tmp_path / "r.csv").read_bytes().replace(b"\n", b"\r"))
    with pytest.raises(RecordingError, match=r"mac.csv: the lines end in a carriage return "
                       r"alone .* convert them to LF"):
        read(path)


def test_a_trailing_delimiter_is_a_line_end_not_a_column(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text()
    path = tmp_path / "trailing.csv"
    path.write_text("\n".join(line + "," if line and not line.startswith("#") else line
                              for line in text.split("\n")))
    back = read(path)
    assert back.names == COLUMNS
    for name in COLUMNS:
        np.testing.assert_array_equal(back[name], run[name])


def test_a_column_without_a_name_inside_the_header_is_named(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text().replace("rate_dph,", "rate_dph,,")
    path = tmp_path / "hole.csv"
    path.write_text(text)
    with pytest.raises(RecordingError, match=r"hole.csv: column 4 after 'rate_dph' has no name"):
        read(path)


def test_a_space_separated_file_is_named_as_such(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text()
    path = tmp_path / "spaces.csv"
    path.write_text("\n".join(line if line.startswith("#") else line.replace(",", "  ")
                              for line in text.split("\n")))
    with pytest.raises(RecordingError, match=r"spaces.csv: the header line 'time_s  freq_hz.*"
                       r"separated by spaces"):
        read(path)


def test_duplicated_column_names_are_named_with_their_positions(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text().replace(",chamber_c", ",rate_dph")
    path = tmp_path / "dup.csv"
    path.write_text(text)
    with pytest.raises(RecordingError, match=r"dup.csv: columns 3 and 4 of the header are both "
                       r"named 'rate_dph'"):
        read(path)


def test_swapped_frequency_and_rate_headers_are_named_and_the_fix_works(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text()
    swapped = text.replace("freq_hz,rate_dph", "rate_dph,freq_hz")
    path = tmp_path / "swapped.csv"
    path.write_text(swapped)
    with pytest.raises(RecordingError, match=r"swapped.csv: columns 'freq_hz' \(median [\d.]+\) "
                       r"and 'rate_dph' .* look swapped.*--col freq_hz=rate_dph --col "
                       r"rate_dph=freq_hz") as caught:
        read(path)
    assert "kHz" not in str(caught.value)
    back = read(path, columns={"freq_hz": "rate_dph", "rate_dph": "freq_hz"})
    np.testing.assert_array_equal(back["freq_hz"], run["freq_hz"])
    np.testing.assert_array_equal(back["rate_dph"], run["rate_dph"])


def test_a_frequency_in_khz_is_still_named_as_khz(run, tmp_path):
    columns = {k: run[k] for k in run.names} | {"freq_hz": run["freq_hz"] / 1000.0}
    path = write(Recording(columns, run.metadata), tmp_path / "khz.parquet")
    with pytest.raises(RecordingError, match="freq_hz looks like kHz"):
        read(path)


def test_a_spreadsheets_padding_of_empty_columns_is_left_out():
    # the PAN hand log (tests/data/pan-cold-test) pads every line with 14 empty fields
    from hrgtc.recording.io import open_source

    handlog = (Path(__file__).resolve().parents[1] / "data" / "pan-cold-test"
               / "pan_etu_cold_handlog_2020-03-07.csv")
    with open_source(handlog) as source:
        assert source.names == ["Time", "F2 (F)", "F3 (F)", "F4 (F)", "C1 (C)"]
        table = source.read(["C1 (C)"], set())
    assert table.column(0).to_pylist()[:3] == [21.5, 21.9, 22.2]  # the log's first rows


def test_an_axis_frequency_outside_the_models_band_is_a_plain_number(three_axis, tmp_path):
    from hrgtc.recording import ReadOptions

    columns = {k: np.array(three_axis[k]) for k in three_axis.names}
    columns["freq_hz_y"][700] = 4500.25
    path = write(Recording(columns, three_axis.metadata), tmp_path / "band.parquet")
    options = ReadOptions(axis="y", freq_band_hz=(4400.0, 4450.0))
    with pytest.raises(RecordingError, match=r"band.parquet: column freq_hz_y, row 700: 4500.25 "
                       r"is outside the band") as caught:
        list(options.chunks(path))
    assert "np.float64" not in str(caught.value)


def test_a_file_without_a_header_line_says_so_when_columns_are_missing(run, tmp_path):
    text = write(run, tmp_path / "r.csv").read_text().split("\n")
    header = next(i for i, line in enumerate(text) if not line.startswith("#"))
    path = tmp_path / "headless.csv"
    path.write_text("\n".join(text[:header] + text[header + 1:]))  # metadata kept, names gone
    with pytest.raises(RecordingError, match=r"headless.csv: required column\(s\) 'time_s', "
                       r"'freq_hz', 'rate_dph' missing \(the file has no header line, so its "
                       r"columns are \['column_1', 'column_2', 'column_3', 'column_4'\]\); .*"
                       r"--col time_s="):
        read(path)
