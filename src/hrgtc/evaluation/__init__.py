"""Evaluation: stage 5, how much better the gyro got.

Takes a model (one axis or many) and a run and gives, in one pass (``evaluate``: a
``run_pass`` per axis, the run read once), the raw
and compensated bias stability (Section 4.2 of [1]: 3.0143 -> 0.5848 °/h),
Allan deviations and noise terms (``allan``), the out-of-range shares and the
residual against the simulator's true bias; ``metrics`` holds the figures of
merit themselves.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.core import lazy_names

#: Public name -> the module of this package that defines it, imported on first use
#: (PEP 562): ``hrgtc.evaluation.allan`` alone costs no drift model, scipy or pyarrow.
#: (``run_pass`` is the function until the module of that name is imported by its path.)
_NAMES = {
    "AllanResult": "allan", "allan_deviation": "allan",
    "Evaluation": "evaluation_result",
    "DEFAULT_TAUS_S": "metrics", "ResidualResult": "metrics", "bias_stability": "metrics",
    "bias_stability_table": "metrics", "residual_against_truth": "metrics",
    "NoiseTerms": "noise", "noise_terms": "noise",
    "BlockMeans": "plot_blocks", "block_rows": "plot_blocks",
    "run_pass": "run_pass", "RunEvaluation": "run_evaluation", "evaluate": "run_evaluation",
}


__getattr__, __dir__ = lazy_names(__name__, _NAMES, globals())


__all__ = [
    "DEFAULT_TAUS_S",
    "AllanResult",
    "BlockMeans",
    "Evaluation",
    "NoiseTerms",
    "ResidualResult",
    "RunEvaluation",
    "allan_deviation",
    "bias_stability",
    "bias_stability_table",
    "block_rows",
    "evaluate",
    "noise_terms",
    "residual_against_truth",
    "run_pass",
]
