"""Evaluation: stage 5, how much better the gyro got.

Takes a unit model and a run and gives, in one pass (``run_pass``), the raw
and compensated bias stability (Section 4.2 of [1]: 3.0143 -> 0.5848 °/h),
Allan deviations and noise terms (``allan``), the out-of-range shares and the
residual against the simulator's true bias; ``metrics`` holds the figures of
merit themselves.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.evaluation.allan import AllanResult, allan_deviation
from hrgtc.evaluation.evaluation_result import Evaluation
from hrgtc.evaluation.metrics import (
    DEFAULT_TAUS_S,
    ResidualResult,
    bias_stability,
    bias_stability_table,
    residual_against_truth,
)
from hrgtc.evaluation.noise import NoiseTerms, noise_terms
from hrgtc.evaluation.plot_blocks import BlockMeans, block_rows
from hrgtc.evaluation.run_pass import evaluate, run_pass

__all__ = [
    "DEFAULT_TAUS_S",
    "AllanResult",
    "BlockMeans",
    "Evaluation",
    "NoiseTerms",
    "ResidualResult",
    "allan_deviation",
    "bias_stability",
    "bias_stability_table",
    "block_rows",
    "evaluate",
    "noise_terms",
    "residual_against_truth",
    "run_pass",
]
