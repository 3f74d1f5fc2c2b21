"""hrgtc.recording.info: the summary of a file whose column names are no layout fields."""

from __future__ import annotations

import numpy as np

from hrgtc.recording import describe


def test_columns_named_with_colons_and_braces_are_described(tmp_path):
    """A column name is printed as it is, even one a layout field cannot hold: a TDMS
    channel named by its clock time ('07/09/2012 06:58:03') or a name with braces."""
    n = 600
    path = tmp_path / "odd.csv"
    table = np.column_stack([np.arange(n) * 0.1, np.full(n, 4424.0), np.zeros(n),
                             np.arange(n, dtype=float), np.ones(n)])
    np.savetxt(path, table, delimiter=",", comments="",
               header="time_s,freq_hz,rate_dph,07/09/2012 06:58:03,a{b}")
    text = describe(path).summary().text()
    assert "07/09/2012 06:58:03" in text and "a{b}" in text
