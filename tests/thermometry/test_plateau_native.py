"""The soak plateaus' C passes (``_plateau_native.c``) compute the bits of the numba
kernels they replaced (``thermometry/_plateau_numba_reference.py``), and their module does
not import numba.

``block_index`` on clocks far from zero, times on and beside block edges, block lengths
that are not binary fractions, lengths 0 to 2; ``block_sums`` on NaN, infinite and
signed-zero values, empty blocks, one block, and a million samples. Sums are compared
bit for bit (``.view(np.int64)``: a NaN's payload and a zero's sign too).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from hrgtc.thermometry import _plateau_kernel as native
from thermometry import _plateau_numba_reference as reference


def bits(values) -> np.ndarray:
    return np.asarray(values, dtype=np.float64).view(np.int64)


def clocks(rng: np.random.Generator):
    yield np.empty(0)
    yield np.array([1.7e9])
    yield np.array([0.0, 0.1])
    yield np.arange(100_000) / 200.0
    yield 1.7e9 + 0.123 + np.cumsum(rng.uniform(0.5, 1.5, 50_000))
    edges = -35.5 + (1.0 / 3.0) * np.arange(1, 400)
    yield np.unique(np.concatenate([[-35.5], edges, np.nextafter(edges, np.inf),
                                    np.nextafter(edges, -np.inf)]))


@pytest.mark.parametrize("block_s", [10.0, 0.1, 1.0 / 3.0, 7.3, 1e-3, 3600.0])
def test_block_index_is_the_numba_kernels(block_s):
    for time_s in clocks(np.random.default_rng(int(block_s * 1000))):
        got = native.block_index(time_s, block_s)
        want = reference.block_index(time_s, block_s)
        assert got.dtype == want.dtype == np.intp
        np.testing.assert_array_equal(got, want)


def test_floor_divide_is_the_numba_kernels():
    rng = np.random.default_rng(2)
    a = np.concatenate([rng.uniform(-1e10, 1e10, 3000), rng.integers(-50, 50, 300) * 0.1,
                        [0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300]])
    for b in (0.1, 1.0 / 3.0, -0.7, 10.0, 1e-6, -1e6):
        for value in a:
            got, want = native._floor_divide(float(value), b), reference._floor_divide(value, b)
            assert bits(got) == bits(want), (value, b)


def sums_of(kernel, block, time_s, freq, ref, chamber):
    return kernel.block_sums(block, time_s, freq, ref, chamber)


@pytest.mark.parametrize("n", [0, 1, 2, 999, 1_000_000])
def test_block_sums_are_the_numba_kernels(n):
    rng = np.random.default_rng(n)
    time_s = 1.7e9 + np.cumsum(rng.uniform(0.05, 0.15, n))
    block = native.block_index(time_s, 10.0)
    block[(block > 3) & (block < 6)] = 2  # blocks 3 to 5 empty, block 2 not in time order
    freq = 4417.0 + 1e-2 * rng.standard_normal(n)
    chamber = 20.0 + 0.05 * rng.standard_normal(n)
    if n > 10:
        odd = rng.integers(0, n, 8)
        freq[odd[:4]] = [np.nan, np.inf, -np.inf, -0.0]
        chamber[odd[4:]] = [np.nan, -np.inf, 0.0, -0.0]
    ref = float(freq[0]) if n else 0.0
    got = sums_of(native, block, time_s, freq, ref, chamber)
    want = sums_of(reference, block, time_s, freq, ref, chamber)
    np.testing.assert_array_equal(got[0], want[0], strict=True)
    for mine, theirs in zip(got[1:], want[1:], strict=True):
        np.testing.assert_array_equal(bits(mine), bits(theirs))


def test_a_block_outside_the_bins_is_refused():
    with pytest.raises(ValueError, match="block"):
        native._native.block_sums(np.array([0, 3]), np.zeros(2), np.zeros(2), 0.0,
                                  np.zeros(2), np.zeros(2, np.int64), *[np.zeros(2)] * 4)
    with pytest.raises(TypeError, match="block"):
        native.block_sums(np.array([0, 1], dtype=np.int32), np.zeros(2), np.zeros(2), 0.0,
                          np.zeros(2))
    with pytest.raises(ValueError, match="chamber_c"):
        native.block_sums(np.array([0, 1]), np.zeros(2), np.zeros(2), 0.0, np.zeros(3))


def test_the_module_does_not_import_numba():
    code = ("import sys; import hrgtc.thermometry._plateau_kernel; "
            "import hrgtc.thermometry.plateaus; print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
