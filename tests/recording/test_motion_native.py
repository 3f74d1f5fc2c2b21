"""The at-rest detector's C loops (``_motion_native.c`` behind ``_motion_kernel``) give,
bit for bit, what the numba kernels they replace gave (``_motion_numba_reference``, the
numba text as it was): every value compared as int64 bits, every mask exactly, on random
and adversarial inputs (NaN, ±inf, ties, zeros of both signs, huge offsets, lengths 0, 1,
2, odd and even, blocks on both sides of the bracketing median's 2048)."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.recording import _motion_kernel as kernel
from recording import _motion_numba_reference as ref

LENGTHS = (0, 1, 2, 3, 4, 5, 16, 17, 2047, 2048, 2049, 4096, 4097, 20_000, 20_001)


def bits(value) -> np.ndarray:
    return np.asarray(value, dtype=np.float64).view(np.int64)


def same(a, b) -> bool:
    """Same bits (floats) or same values (ints, bools), same shape."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        return a.shape == b.shape and np.array_equal(bits(a), bits(b))
    return a.dtype == b.dtype and np.array_equal(a, b)


def values_of(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    x = {
        "normal": lambda: rng.standard_normal(n),
        "ties": lambda: np.round(2 * rng.standard_normal(n)),
        "signed_zeros": lambda: rng.choice([0.0, -0.0, 0.0, -0.0, 1.0, -1.0], n),
        "all_zeros": lambda: np.where(rng.random(n) < 0.5, 0.0, -0.0),
        "offset": lambda: 1e15 + np.round(rng.standard_normal(n) * 8),
        "sorted": lambda: np.sort(rng.standard_normal(n)),
        "reversed": lambda: np.sort(rng.standard_normal(n))[::-1].copy(),
        "mostly_one": lambda: np.where(rng.random(n) < 0.6, 1.0, rng.standard_normal(n)),
        "infinite": lambda: np.where(rng.random(n) < 0.1,
                                     rng.choice([np.inf, -np.inf], n), rng.standard_normal(n)),
        "nan": lambda: np.where(rng.random(n) < 0.05, np.nan, rng.standard_normal(n)),
    }[kind]()
    return np.ascontiguousarray(x, dtype=np.float64)


KINDS = ("normal", "ties", "signed_zeros", "all_zeros", "offset", "sorted", "reversed",
         "mostly_one", "infinite", "nan")


@pytest.mark.parametrize("kind", KINDS)
def test_median_is_numbas_bit_for_bit(kind):
    rng = np.random.default_rng(len(kind))
    for n in LENGTHS:
        values = values_of(kind, n, rng)
        before = values.copy()
        assert same(kernel.median(values), ref.median(values)), (kind, n)
        assert same(values, before)  # the input is not reordered


def test_the_signed_zero_median_is_numbas():
    """Middle values that are zeros of both signs: the sign numba's selection gives."""
    found = set()
    for n in (2, 3, 4, 6, 3000, 3001):
        for seed in range(20):
            values = np.where(np.random.default_rng(seed).random(n) < 0.5, 0.0, -0.0)
            ours, theirs = kernel.median(values), ref.median(values)
            assert same(ours, theirs), (n, seed)
            found.add(np.signbit(ours))
    assert found == {True, False}  # both signs occur: the comparison can fail


def differences_input(kind: str, n: int, rng: np.random.Generator):
    x = values_of(kind, n, rng)
    breaks = rng.random(max(n - 1, 0)) < 0.05
    return x, breaks


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("mode", [kernel.FORWARD, kernel.INSIDE, kernel.DEVIATION,
                                  kernel.INSIDE_FORWARD])
def test_difference_kernels_are_numbas(kind, mode):
    rng = np.random.default_rng(100 + mode)
    for n in (1, 2, 3, 50, 2049, 20_001):
        x, breaks = differences_input(kind, n, rng)
        for centre in (0.0, -0.0, 0.25):
            for size in (1, 7, 64):
                count, sample = kernel.difference_sample(x, breaks, mode, centre, size)
                count_ref, sample_ref = ref.difference_sample(x, breaks, mode, centre, size)
                assert count == count_ref and same(sample, sample_ref), (n, size)
            assert same(kernel.gather(x, breaks, mode, centre, count),
                        ref.gather(x, breaks, mode, centre, count))
            ordered = np.sort(sample_ref) if sample_ref.size else np.array([0.0])
            for lo, hi in ((ordered[0], ordered[-1]), (ordered[len(ordered) // 2],) * 2,
                           (-np.inf, np.inf), (0.0, 0.0), (-0.0, 1.0)):
                ours = kernel.bracket(x, breaks, mode, centre, lo, hi)
                theirs = ref.bracket(x, breaks, mode, centre, lo, hi)
                assert ours[0::3] == theirs[0::3] and ours[1] == theirs[1]
                assert same(ours[2], theirs[2])


def test_gather_refuses_a_wrong_count():
    x = np.arange(10.0)
    with pytest.raises(ValueError, match="9 differences selected, out holds 5"):
        kernel.gather(x, np.zeros(9, dtype=bool), kernel.INSIDE, 0.0, 5)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 1000])
def test_steps_breaks_and_segments_are_numbas(n):
    rng = np.random.default_rng(n)
    t = np.cumsum(rng.exponential(0.01, n))
    if n > 3:
        t[[1, n // 2]] = [np.nan, -np.inf]
        t[n // 3] = t[n // 3 - 1]
        t[-1] = np.inf
    for limit in (0.0, -0.0, 0.01, 0.05, np.inf):
        assert same(kernel.find_breaks(t, limit), ref.find_breaks(t, limit))
        assert same(kernel.steps_over(t, limit), ref.steps_over(t, limit))
    breaks = ref.find_breaks(t, 0.02)
    assert same(kernel.segment_index(breaks), ref.segment_index(breaks))
    assert kernel.first_not_finite(t) == ref.first_not_finite(t)
    assert kernel.first_not_finite(np.ones(n)) == ref.first_not_finite(np.ones(n)) == -1


def channel(rng, m: int, kind: str) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(m) * 0.01 + rng.uniform(0, 0.002, m)
    if kind == "ties_in_time":
        t = np.round(t, 1)
    x = 3.0 + 0.02 * rng.standard_normal(m)
    x[m // 5:m // 5 + 40] += 1.0  # handling
    x[m // 2:] += 0.3  # a step of the still level
    shake = x[m // 3:m // 3 + 60]
    shake += 0.5 * rng.standard_normal(shake.size)  # shaking
    x[-30:-25] = x.max() + 1.0  # a clipped plateau
    x[10:14] = x.min() - 1.0
    if kind == "quantised":
        x = np.round(x, 2)
    elif kind == "signed_zeros":
        x = np.where(rng.random(m) < 0.5, 0.0, -0.0)
    return np.ascontiguousarray(t), np.ascontiguousarray(x)


def constants_for(x, var_rows, min_run, held, level=0.12, diff_sigma=0.03):
    return (5, var_rows, min_run, level, diff_sigma, 0.0, 1.482602218505602, 3 * diff_sigma,
            level, float(x.max()), float(x.min()), 3, level > 0, held)


@pytest.mark.parametrize("kind", ["plain", "quantised", "ties_in_time", "signed_zeros"])
@pytest.mark.parametrize("m", [1, 2, 33, 500, 6001, 30_000])
def test_segment_tests_are_numbas(kind, m):
    rng = np.random.default_rng(m)
    t, x = channel(rng, m, kind)
    for rows in (8, 3000):
        blocks = max(m // rows, 1)
        edges = np.linspace(0, m, blocks + 1).astype(np.int64)
        for var_rows, min_run, held, level, sigma in ((32, 2, False, 0.12, 0.03),
                                                      (100, 10, True, 0.12, 0.03),
                                                      (32, 2, True, 0.0, 0.0),
                                                      (7, 3, False, 1e-3, 1e-4)):
            constants = constants_for(x, var_rows, min_run, held, level, sigma)
            start = rng.random((4, m)) < 0.01  # OR-ed into: the masks are not zeroed
            ours, theirs = start.copy(), start.copy()
            kernel.segment_tests(t, x, edges, kernel.ChannelTests(*constants), tuple(ours))
            ref.segment_tests(t, x, edges, ref.ChannelTests(*constants), tuple(theirs))
            assert np.array_equal(ours, theirs), (rows, var_rows)
            if m >= 500 and kind != "signed_zeros" and level > 0:
                assert ours[:3].any()  # something is found: the comparison can fail


def test_segment_tests_refuse_bad_edges_instead_of_crashing():
    t, x = np.arange(10.0), np.zeros(10)
    out = tuple(np.zeros((4, 10), dtype=bool))
    constants = kernel.ChannelTests(*constants_for(x, 32, 2, False))
    for edges in ([0, 5, 5, 10], [0, 11], [1, 10], [0]):
        with pytest.raises(ValueError, match="edges"):
            kernel.segment_tests(t, x, np.array(edges), constants, out)
    with pytest.raises(TypeError, match="values must be a contiguous 1-D float64"):
        kernel.segment_tests(t, x.astype(np.float32), np.array([0, 10]), constants, out)
    with pytest.raises(TypeError, match="level must be a contiguous 1-D bool"):
        kernel.segment_tests(t, x, np.array([0, 10]), constants,
                             (np.zeros(10), *out[1:]))


@pytest.mark.parametrize("n", [0, 1, 2, 7, 5000])
def test_guard_and_isolated_runs_are_numbas(n):
    rng = np.random.default_rng(n + 3)
    found = tuple(rng.random(n) < p for p in (0.01, 0.005, 0.002, 0.003))
    cuts = np.sort(rng.choice(np.arange(1, n), min(5, max(n - 1, 0)), replace=False)) \
        if n > 1 else np.zeros(0, dtype=np.int64)
    starts = np.r_[0, cuts].astype(np.int64)
    stops = np.r_[cuts, n].astype(np.int64)
    for after, before in ((0, 0), (3, 2), (500, 100)):
        seed = rng.random(n) < 0.01
        stale = rng.random(n) < 0.5  # guarded is overwritten, whatever it held
        ours = [seed.copy(), stale.copy()]
        theirs = [seed.copy(), stale.copy()]
        kernel.guard(found, starts, stops, after, before, *ours)
        ref.guard(found, starts, stops, after, before, *theirs)
        assert np.array_equal(ours[0], theirs[0]) and np.array_equal(ours[1], theirs[1])
        stepped = rng.random(n) < 0.3
        out_ours, out_theirs = seed.copy(), seed.copy()
        kernel.isolated_runs(stepped, ours[0], out_ours)
        ref.isolated_runs(stepped, theirs[0], out_theirs)
        assert np.array_equal(out_ours, out_theirs)


def test_guard_refuses_segments_out_of_range():
    masks = tuple(np.zeros((6, 10), dtype=bool))
    with pytest.raises(ValueError, match="segments"):
        kernel.guard(masks[:4], np.array([0]), np.array([11]), 1, 1, masks[4], masks[5])


def digest_of(*pieces: np.ndarray) -> int:
    state = kernel.digest_start()
    for piece in pieces:
        kernel.digest_update(state, np.ascontiguousarray(piece))
    return kernel.digest(state)


def test_the_digest_of_pieces_is_that_of_the_whole():
    """``compensate`` digests the detector's chunks and the compensating pass's rows, cut
    elsewhere: any cut gives the same digest."""
    rng = np.random.default_rng(4)
    x = rng.standard_normal(10_007)
    whole = digest_of(x)
    for _ in range(20):
        cuts = np.sort(rng.integers(0, x.size, rng.integers(1, 12)))
        assert digest_of(*np.split(x, cuts)) == whole
    assert digest_of(x[:0]) == digest_of() != digest_of(np.zeros(1))


def test_one_changed_bit_always_changes_the_digest():
    """Every bit of values at each of the four lanes' positions, the first and the last;
    signed zeros and NaN payloads are other bits; a row shifted or dropped changes it."""
    rng = np.random.default_rng(5)
    x = rng.standard_normal(1001)
    whole = digest_of(x)
    for i in (0, 1, 2, 3, 500, 999, 1000):
        for bit in range(64):
            y = x.copy()
            y.view(np.int64)[i] ^= np.int64(1) << np.int64(bit)
            assert digest_of(y) != whole, (i, bit)
    assert digest_of(np.array([0.0, 1.0])) != digest_of(np.array([-0.0, 1.0]))
    nan = np.array([np.nan]).view(np.int64)
    assert digest_of(nan.view(np.float64)) != digest_of((nan + 1).view(np.float64))
    assert digest_of(np.r_[x[1:], x[-1]]) != whole and digest_of(x[1:]) != whole
    digests = {digest_of(rng.standard_normal(64)) for _ in range(2000)}
    assert len(digests) == 2000
