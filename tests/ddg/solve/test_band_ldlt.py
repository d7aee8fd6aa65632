"""LDL^T without pivoting of symmetric band matrices (ddg.solve.band_ldlt) against dense numpy."""
import numpy as np
import pytest

from ddg.solve import band_ldlt as bl
from ddg.solve.band_ldlt import Inertia, UnreliablePivot, band_ldlt, inertia, ldlt_solve


def random_band(n, bandwidth, definite, seed):
    """Lower band storage of a random symmetric band matrix, diagonally shifted: the diagonal is
    1 + the absolute row sum of the off-diagonal entries (strictly diagonally dominant, so every
    leading principal minor is nonzero), with random signs when not definite."""
    rng = np.random.default_rng(seed)
    band = rng.standard_normal((bandwidth + 1, n))
    for d in range(1, bandwidth + 1):
        band[d, n - d:] = 0.0
    rowsum = np.zeros(n)
    for d in range(1, bandwidth + 1):
        rowsum[: n - d] += np.abs(band[d, : n - d])
        rowsum[d:] += np.abs(band[d, : n - d])
    shift = 1.0 + rowsum + np.abs(rng.standard_normal(n))
    signs = np.ones(n) if definite else rng.choice([-1.0, 1.0], size=n)
    band[0] = signs * shift
    return band


def dense(band):
    n = band.shape[1]
    a = np.diag(band[0])
    for d in range(1, band.shape[0]):
        off = np.diag(band[d, : n - d], -d)
        a += off + off.T
    return a


def unit_lower(factor):
    n = factor.shape[1]
    low = np.eye(n)
    for d in range(1, factor.shape[0]):
        low += np.diag(factor[d, : n - d], -d)
    return low


CASES = [(n, b, definite) for n in (10, 200) for b in (1, 5, 30) for definite in (True, False) if b < n]


@pytest.mark.parametrize("n,bandwidth,definite", CASES + [(200, 40, True), (200, 40, False)])
def test_factor_solve_inertia_against_dense(n, bandwidth, definite):
    # bandwidth 40 takes the blocked (BLAS) path, the others the column loop
    band = random_band(n, bandwidth, definite, seed=n * 100 + bandwidth + definite)
    a = dense(band)
    f = band_ldlt(band)
    assert f.reliable and f.stopped_at is None
    low = unit_lower(f.factor)
    assert np.array_equal(f.factor[0], np.ones(n))
    rebuilt = low @ np.diag(f.d) @ low.T
    assert np.linalg.norm(rebuilt - a) <= 1e-12 * np.linalg.norm(a)
    rng = np.random.default_rng(7)
    rhs = rng.standard_normal(n)
    x_ref = np.linalg.solve(a, rhs)
    assert np.linalg.norm(f.solve(rhs) - x_ref) <= 1e-12 * np.linalg.norm(x_ref)
    many = rng.standard_normal((n, 3))
    assert np.allclose(f.solve(many), np.linalg.solve(a, many), rtol=1e-11, atol=1e-13)
    w = np.linalg.eigvalsh(a)
    expected = Inertia(int(np.sum(w < 0)), 0, int(np.sum(w > 0)))
    assert f.inertia() == expected == inertia(band)
    assert (expected.negative == 0) == definite
    assert np.allclose(ldlt_solve(band, rhs), x_ref, rtol=1e-11, atol=1e-13)
    assert np.array_equal(band, random_band(n, bandwidth, definite, seed=n * 100 + bandwidth + definite))  # input kept


@pytest.mark.parametrize("definite", [True, False])
def test_blocked_kernel_matches_column_loop(definite):
    """Small panels, leaves and chunks, so that every edge of the blocking (last partial panel,
    a chunk narrower than the band, columns near the end of the matrix) occurs at n = 61."""
    band = random_band(61, 9, definite, seed=3)
    plain = np.array(band.T, order="C")
    blocked = plain.copy()
    assert bl.ldlt_transposed(plain, 0.0, 8, 3, 5, 10 ** 9) == (0, -1, -1)  # column loop only
    for panel, leaf, chunk in ((8, 3, 5), (7, 7, 2), (64, 8, 64)):
        blocked = np.array(band.T, order="C")
        assert bl.ldlt_transposed(blocked, 0.0, panel, leaf, chunk, 0) == (0, -1, -1)
        assert np.allclose(blocked, plain, rtol=1e-13, atol=1e-13)


def test_exactly_singular_leading_minor_is_reported():
    # A = [[1, 1, 0], [1, 1, 1], [0, 1, 1]] is nonsingular (det -1) but its leading 2 x 2 minor is 0
    band = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 0.0]])
    f = band_ldlt(band)
    assert not f.reliable
    assert f.stopped_at == 1 and list(f.tiny) == [1, 2]
    assert np.isnan(f.d[2])
    with pytest.raises(UnreliablePivot, match="pivot 1 of 3 is exactly zero"):
        f.inertia()
    with pytest.raises(UnreliablePivot):
        f.inertia(strict=False)  # nothing to count after the stop
    with pytest.raises(UnreliablePivot):
        f.solve(np.ones(3))
    with pytest.raises(UnreliablePivot):
        inertia(band)
    # the same matrix, blocked path
    wide = np.zeros((40, 3))
    wide[:2] = band
    assert band_ldlt(wide).stopped_at == 1
    # [[0, 1], [1, 0]]: the first pivot is zero
    assert band_ldlt(np.array([[0.0, 0.0], [1.0, 0.0]])).stopped_at == 0


def test_pivot_zero_to_rounding_counts_as_zero():
    # A = [[1, 1], [1, 1 + eps]]: the second pivot eps <= n eps max|A_jj| = 2 eps (1 + eps)
    eps = np.finfo(float).eps
    band = np.array([[1.0, 1.0 + eps], [1.0, 0.0]])
    f = band_ldlt(band)
    assert not f.reliable and f.stopped_at is None and list(f.tiny) == [1]
    with pytest.raises(UnreliablePivot, match=r"pivot 1 of 2 has \|d\|"):
        f.inertia()
    assert f.inertia(strict=False) == Inertia(0, 1, 1)
    with pytest.raises(UnreliablePivot):
        f.solve(np.ones(2))
    # scaled up, the same pivot is well above the tolerance
    assert band_ldlt(np.array([[1.0, 1.5], [1.0, 0.0]])).inertia() == Inertia(0, 0, 2)


def test_non_finite_entry_is_reported():
    band = random_band(10, 2, True, seed=1)
    band[0, 4] = np.nan
    f = band_ldlt(band)
    assert f.stopped_at == 4 and not f.reliable


def test_bad_shapes():
    with pytest.raises(ValueError):
        band_ldlt(np.ones(5))
    f = band_ldlt(random_band(10, 2, True, seed=2))
    with pytest.raises(ValueError):
        f.solve(np.ones(9))
    with pytest.raises(ValueError):
        f.solve(np.float64(1.0))
