"""``hrgtc paper``: the paper's Table 1 -> Eq. (18) -> Table 2, recomputed."""

from __future__ import annotations

import typer
from rich.table import Table

from hrgtc.cli._app import app, console, library_errors, print_json


@app.command("paper")
def paper_command(
    json_output: bool = typer.Option(False, "--json", help="Print JSON instead of tables."),
) -> None:
    """Reproduce Eq. (18) from Table 1 and Table 2 from Eq. (18) of Wang et al. (2012).

    Example: hrgtc paper --json
    """
    from hrgtc.thermometry import paper

    with library_errors():
        result = paper.reproduce()
    if json_output:
        print_json(result.to_dict())
        return
    table1 = Table(title="Table 1 of the paper: settled frequency of each soak")
    table1.add_column("Temperature (°C)", justify="right")
    table1.add_column("Natural frequency (Hz)", justify="right")
    for t, f in zip(paper.TABLE1_TEMPERATURE_C, paper.TABLE1_FREQUENCY_HZ, strict=True):
        table1.add_row(f"{t:g}", f"{f:,.2f}")
    console.print(table1)

    eq18 = Table(title="Eq. (18): f = c3·T³ + c2·T² + c1·T + c0, least squares on Table 1")
    for column in ("term", "fitted (full precision)", "fitted (printed digits)", "Eq. (18)"):
        eq18.add_column(column, justify="right")
    for name, full, rounded, published in zip(
        ("T³", "T²", "T", "1"),
        result.coefficients_high_first,
        result.rounded_high_first,
        paper.EQ18_PRINTED_HIGH_FIRST,
        strict=True,
    ):
        eq18.add_row(name, f"{full:.9g}", f"{rounded}", f"{published}")
    console.print(eq18)

    table2 = Table(title="Table 2: temperature calculated from the frequency by inverting the fit")
    for column in ("Frequency (Hz)", "Actual (°C)", "Paper (°C)", "hrgtc (°C)", "difference (°C)"):
        table2.add_column(column, justify="right")
    for f, actual, published, computed in zip(
        paper.TABLE2_FREQUENCY_HZ,
        paper.TABLE2_ACTUAL_C,
        paper.TABLE2_CALCULATED_C,
        result.table2_computed_c,
        strict=True,
    ):
        table2.add_row(
            f"{f:,.2f}", f"{actual:g}", f"{published:g}", f"{computed:.4f}",
            f"{computed - published:+.4f}",
        )
    console.print(table2)
