"""The compiled part of hrgtc: the octave Allan sums (src/hrgtc/evaluation/_allan_octave.c)
and the kernels of the at-rest detector, the spike filter, the df/dt filter, the soak
plateaus and the extended-precision residuals (``_*_native.c``, their checks at the
boundary in src/hrgtc/_buffers.h).

Everything else is in pyproject.toml; ``pip install -e .`` (``make .venv/.installed``)
builds the modules in place. Why C: docs/architecture.md, "The native Allan module",
"The native at-rest detector" and "The native kernels".
"""

import sys

from setuptools import Extension, setup

# The rounding as written (no FMA contraction, no fast-math); -O3 for the vector loops.
FLAGS = [] if sys.platform == "win32" else ["-O3", "-ffp-contract=off"]


def kernel(module: str) -> Extension:
    """A kernel's C module ``src/hrgtc/<module>.c``, beside the Python module calling it."""
    return Extension("hrgtc." + module.replace("/", "."), [f"src/hrgtc/{module}.c"],
                     depends=["src/hrgtc/_buffers.h"], extra_compile_args=FLAGS)


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
        kernel("recording/_spike_native"),
        kernel("drift/_rate_native"),
        kernel("thermometry/_plateau_native"),
        kernel("drift/_extended_native"),
    ]
)
