"""``hrgtc paper``: the paper's Table 1 -> Eq. (18) -> Table 2, recomputed."""

from __future__ import annotations

import typer

from hrgtc.cli._app import console, library_errors, print_json


def paper_command(
    json_output: bool = typer.Option(False, "--json", help="Print JSON instead of tables."),
) -> None:
    """Reproduce the paper's thermometer: its cubic from Table 1, then Table 2 from the cubic.

    The paper: Wang et al. (2012), Table 1 -> Eq. (18) -> Table 2.

    Example: hrgtc paper --json
    """
    from hrgtc.cli.summary_tables import print_summary
    from hrgtc.evaluation.calibration_figures import paper_tables
    from hrgtc.thermometry import paper

    with library_errors():
        result = paper.reproduce()
    if json_output:
        print_json(result.to_dict())
        return
    print_summary(paper_tables(result), console)
