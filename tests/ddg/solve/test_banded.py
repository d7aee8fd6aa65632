"""Banded symmetric linear algebra against dense numpy."""
import numpy as np
import pytest

from ddg.assembly.band_scatter import add_pair_block, add_symmetric_block
from ddg.solve.banded import SymmetricBanded


def random_banded(n, bandwidth, lowest, seed=0):
    rng = np.random.default_rng(seed)
    band = 0.1 * rng.standard_normal((bandwidth + 1, n))
    band[0] = np.linspace(lowest, 50.0, n)
    for d in range(1, bandwidth + 1):
        band[d, n - d:] = 0.0
    return SymmetricBanded(band)


@pytest.mark.parametrize("lowest", [2.0, -1.0])  # positive definite, and indefinite
def test_lowest_eigenpairs_match_dense(lowest):
    K = random_banded(300, 10, lowest)
    dense = K.to_dense()
    w_ref, v_ref = np.linalg.eigh(dense)
    w, v = K.lowest_eigenpairs(3, vectors=True)
    assert K.cholesky() == (lowest > 0)
    assert np.allclose(w, w_ref[:3], rtol=1e-9, atol=1e-9)
    for i in range(3):
        assert np.linalg.norm(dense @ v[:, i] - w[i] * v[:, i]) < 1e-8


@pytest.mark.parametrize("lowest", [2.0, -1.0])
def test_solve_matvec_restrict(lowest):
    K = random_banded(120, 10, lowest, seed=3)
    dense = K.to_dense()
    rhs = np.arange(120.0)
    assert np.allclose(K.solve(rhs), np.linalg.solve(dense, rhs))
    assert np.allclose(K.matvec(rhs), dense @ rhs)
    assert np.allclose(K.restrict(7, 113).to_dense(), dense[7:113, 7:113])
    s = np.linspace(1.0, 2.0, 120)
    assert np.allclose(K.scaled(s).to_dense(), s[:, None] * dense * s[None, :])


def test_scatter_sums_overlapping_blocks_into_the_band():
    """Symmetric element blocks on arbitrary (distinct) DOFs, and pair blocks C entering as C + C^T
    (with shared DOFs, landing twice on their diagonal), summed into lower band storage equal the
    dense sums."""
    n, bandwidth = 15, 10
    rng = np.random.default_rng(5)
    band = np.zeros((bandwidth + 1) * n)
    dense = np.zeros((n, n))
    for dofs in (np.array([0, 1, 2, 4, 5, 6, 7]), np.array([9, 3, 5, 8, 4, 6, 7]), np.array([14, 8, 10, 12, 13, 11,
                                                                                             9])):
        block = rng.standard_normal((7, 7))
        block = block + block.T
        add_symmetric_block(band, n, dofs, block)
        dense[np.ix_(dofs, dofs)] += block
    rows, cols = np.array([3, 4, 5, 6]), np.array([5, 6, 7, 9])
    cross = rng.standard_normal((4, 4))
    add_pair_block(band, n, rows, cols, cross)
    pair = np.zeros((n, n))
    np.add.at(pair, (rows[:, None], cols[None, :]), cross)
    dense += pair + pair.T
    assert np.allclose(SymmetricBanded(band.reshape(bandwidth + 1, n)).to_dense(), dense, rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_lanczos_lowest_eigenvalue_from_the_cholesky_factor(seed):
    """lambda_min of K v = lambda D v from K's banded Cholesky factor (ddg.solve.lanczos) equals the
    dense value, also when the lowest mode is orthogonal to a constant vector (a mirror-symmetric
    K whose lowest mode is antisymmetric, as on the U branch at a pitchfork)."""
    from ddg.solve.lanczos import lowest_eigenvalue

    n, bandwidth = 120, 6
    K = random_banded(n, bandwidth, 1.0, seed=seed)
    dense = K.to_dense()
    flip = np.eye(n)[::-1]
    dense = 0.5 * (dense + flip @ dense @ flip)  # mirror symmetric
    x = np.linspace(-1.0, 1.0, n)
    odd = x / np.linalg.norm(x)  # antisymmetric, made the lowest mode with eigenvalue 0.05
    dense = dense - (odd @ dense @ odd - 0.05) * np.outer(odd, odd)
    dense = 0.5 * (dense + dense.T)
    band = np.zeros((n - 1 + 1, n))
    for d in range(n):
        band[d, : n - d] = np.diag(dense, -d)
    K = SymmetricBanded(band)
    assert K.cholesky()
    metric = np.random.default_rng(seed).uniform(0.5, 2.0, n)
    metric = 0.5 * (metric + metric[::-1])
    scaled = dense / np.sqrt(np.outer(metric, metric))
    reference = np.linalg.eigvalsh(scaled)[0]
    assert abs(odd @ np.ones(n)) < 1e-12
    assert lowest_eigenvalue(K.cholesky_factor, metric) == pytest.approx(reference, rel=1e-10)


@pytest.mark.parametrize("lowest", [2.0, -1.0])
def test_a_scaled_matrix_inherits_the_cholesky_outcome(lowest):
    """diag(s) A diag(s) after A's Cholesky: the factor diag(s) L equals a fresh factorisation of the
    scaled matrix to round-off (1e-12 of its largest entry; measured ~1e-15), an indefinite A gives an
    indefinite scaled matrix without a trial, and its lowest eigenvalues are the fresh ones'."""
    K = random_banded(300, 10, lowest, seed=4)
    s = np.random.default_rng(5).uniform(0.5, 2.0, 300)
    K.cholesky()
    inherited, fresh = K.scaled(s), SymmetricBanded(K.scaled(s).band.copy())
    assert inherited.positive_definite == fresh.positive_definite == (lowest > 0)
    if lowest > 0:
        scale = np.abs(fresh.cholesky_factor).max()
        assert np.abs(inherited.cholesky_factor - fresh.cholesky_factor).max() < 1e-12 * scale
    np.testing.assert_allclose(inherited.lowest_eigenpairs(2), fresh.lowest_eigenpairs(2), rtol=1e-9, atol=1e-9)
