"""``checks.spectral``: 2-norms and condition numbers by ``eigvalsh`` for symmetric matrices.

The symmetric path must agree with the SVD within its accuracy (both backward stable:
each singular value within a small multiple of ε‖A‖₂, so ‖A‖₂ to a few ε relative and
κ₂ to a few ε·κ₂ relative); every matrix it cannot take (not symmetric entry for entry,
or not finite) must get exactly what the SVD gives; a batch must give each matrix's
single figure bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from pendverify.checks.spectral import conds2, norms2

EPS = np.finfo(float).eps
SEED = 20261129


def spd_batch(n: int, size: int, spread: float, rng) -> np.ndarray:
    """Symmetric positive definite matrices with eigenvalues spread over ``spread`` decades."""
    Q, _ = np.linalg.qr(rng.standard_normal((size, n, n)))
    lam = 10.0 ** rng.uniform(0.0, spread, (size, n))
    A = Q @ (lam[:, :, None] * np.swapaxes(Q, -1, -2))
    return np.triu(A) + np.swapaxes(np.triu(A, 1), -1, -2)  # symmetric entry for entry


@pytest.mark.parametrize("n", [2, 3, 6])
def test_symmetric_figures_agree_with_the_svd_within_its_accuracy(n):
    rng = np.random.default_rng(SEED)
    A = spd_batch(n, 500, 8.0, rng)
    s = np.linalg.svd(A, compute_uv=False)
    norm_err = np.abs(norms2(A) - s[:, 0]) / s[:, 0]
    kappa = s[:, 0] / s[:, -1]
    cond_err = np.abs(conds2(A) - kappa) / kappa
    # ‖A‖: a few ε; κ = σ₁/σₙ: σₙ's absolute error ε‖A‖ is ε·κ relative to σₙ
    assert norm_err.max() <= 8 * n * EPS, norm_err.max()
    assert np.all(cond_err <= 8 * n * EPS * kappa), (cond_err / (EPS * kappa)).max()


def test_a_batch_gives_each_matrix_its_single_figure_bit_for_bit():
    rng = np.random.default_rng(SEED)
    A = spd_batch(3, 200, 6.0, rng)
    A[7, 0, 1] += 1e-3  # one matrix not symmetric: the SVD's, inside a batch
    norms, conds = norms2(A), conds2(A)
    for i, a in enumerate(A):
        assert norms2(a) == norms[i] and conds2(a) == conds[i]


def test_a_matrix_that_is_not_symmetric_gets_exactly_the_svds_figures():
    rng = np.random.default_rng(SEED)
    A = rng.standard_normal((50, 3, 3))
    assert np.array_equal(norms2(A), np.linalg.norm(A, 2, axis=(-2, -1)))
    assert np.array_equal(conds2(A), np.linalg.cond(A))
    # one ulp off symmetric is enough to take the SVD: eigvalsh reads one triangle only
    S = spd_batch(3, 1, 2.0, rng)[0]
    S[0, 1] = np.nextafter(S[0, 1], np.inf)
    assert norms2(S) == float(np.linalg.norm(S, 2))
    wrong = S.copy()
    wrong[0, 1] += 10.0  # a badly asymmetric M: its norm is the whole matrix's, not a triangle's
    assert norms2(wrong) == float(np.linalg.norm(wrong, 2))


def test_a_matrix_holding_nan_is_never_given_to_eigvalsh():
    A = np.array([[np.nan, 0.0], [0.0, 1.0]])  # eigvalsh would return numbers for it
    with pytest.raises(np.linalg.LinAlgError):
        norms2(A)  # what np.linalg.norm(A, 2) does
    assert not np.isfinite(conds2(np.array([[np.inf, 0.0], [0.0, 1.0]])))


def test_a_singular_symmetric_matrix_has_an_infinite_condition_number():
    assert conds2(np.zeros((2, 2)) + np.array([[1.0, 1.0], [1.0, 1.0]])) > 1e15
    assert conds2(np.diag([1.0, 0.0])) == np.inf


def test_a_matrix_that_is_not_finite_is_never_given_to_lapack(capfd):
    """LAPACK prints "On entry to DLASCL parameter number 4 had an illegal value" on standard
    error for an SVD of a matrix holding a NaN or an infinity: such a matrix gets what the SVD
    gives it (a LinAlgError from ``norms2``, NaN from ``conds2``) without it, in a batch too, and
    the finite ones their SVD figures."""
    batch = np.array([[[1.0, 2.0], [3.0, np.nan]], [[np.inf, 0.0], [0.0, 1.0]], [[1.0, 2.0], [0.0, 1.0]]])
    conds = conds2(batch)
    assert np.isnan(conds[:2]).all() and conds[2] == np.linalg.cond(batch[2])
    with pytest.raises(np.linalg.LinAlgError):
        norms2(batch)  # the NaN one
    assert np.isnan(norms2(batch[1])) and norms2(batch[2]) == np.linalg.norm(batch[2], 2)
    assert "illegal value" not in capfd.readouterr().err
