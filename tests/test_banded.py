"""Banded symmetric linear algebra against dense numpy."""
import numpy as np
import pytest

from ddg.solve.banded import BandAssembler, SymmetricBanded


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


def test_assembler_sums_overlapping_blocks():
    n, m = 15, 7
    offsets = np.array([0, 4, 8])
    rng = np.random.default_rng(5)
    blocks = rng.standard_normal((3, m, m))
    blocks = blocks + blocks.transpose(0, 2, 1)
    asm = BandAssembler(n, 10)
    asm.add_family(offsets, m)
    dense = np.zeros((n, n))
    for o, b in zip(offsets, blocks):
        dense[o:o + m, o:o + m] += b
    assert np.allclose(asm.assemble([blocks]).to_dense(), dense)
