"""Report: stage 6, one self-contained HTML file with the paper's figures.

Takes a unit model, its soaks and runs, and gives the report: the settling of each soak
(Fig. 3 of [1]), the T-f fit (Fig. 4), temperature from frequency (Fig. 5, Table 2), raw and
compensated output (Fig. 6), Allan deviations, the stepwise table and the final model. A
report is data, then templates: a kind's data function (``kinds``: the registry; ``paper``:
the report above; ``inputs``: what every kind reads) computes everything it shows, with
``figures`` drawing the plots and ``tables`` the tables, and ``render`` lays it out with the
kind's autoescaped Jinja2 templates (``templates/<kind>/``).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.report.build import build_report

__all__ = ["build_report"]
