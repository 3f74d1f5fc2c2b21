"""The compiled part of hrgtc: the octave Allan sums (src/hrgtc/evaluation/_allan_octave.c)
and the at-rest detector's loops (src/hrgtc/recording/_motion_native.c).

Everything else is in pyproject.toml; ``pip install -e .`` (``make .venv/.installed``)
builds the modules in place. Why C: docs/architecture.md, "The native Allan module" and
"The native at-rest detector".
"""

import sys

from setuptools import Extension, setup

# The rounding as written (no FMA contraction, no fast-math); -O3 for the vector loops.
FLAGS = [] if sys.platform == "win32" else ["-O3", "-ffp-contract=off"]

setup(
    ext_modules=[
        Extension(
            "hrgtc.evaluation._allan_octave",
            ["src/hrgtc/evaluation/_allan_octave.c"],
            extra_compile_args=FLAGS,
        ),
        Extension(
            "hrgtc.recording._motion_native",
            ["src/hrgtc/recording/_motion_native.c"],
            depends=[f"src/hrgtc/recording/_motion_{part}.h"
                     for part in ("order", "segment", "digest")],
            extra_compile_args=FLAGS,
        ),
    ]
)
