"""The 2-norm and the 2-norm condition number of a matrix, or of each matrix of a batch.

Both come from the singular values σ₁ ≥ … ≥ σₙ: ‖A‖₂ = σ₁ and κ₂(A) = σ₁/σₙ.  For a
symmetric matrix the singular values are the eigenvalues' magnitudes, σᵢ = |λᵢ|, and
LAPACK's symmetric eigensolver (``np.linalg.eigvalsh``) finds them with the same
absolute accuracy as its SVD — both are backward stable, each σᵢ or |λᵢ| within a
small multiple of ε‖A‖₂ — at about 40 % of the SVD's cost on the 2 × 2 and 3 × 3
matrices the checks judge by the thousand.  So:

* a matrix that is finite and symmetric entry for entry (M, M⁻¹ and their scaled
  forms M̃ = S^{-½} M S^{-½}, whose (i, j) and (j, i) products round alike) is measured
  by ``eigvalsh``;
* any other finite one (a closed form whose M₁₂ and M₂₁ round differently) by the SVD,
  exactly as ``np.linalg.norm(A, 2)`` and ``np.linalg.cond(A)`` measure it;
* a matrix holding a NaN or an infinity gets what the SVD gives it (``norms2`` raises
  ``LinAlgError`` for a NaN and gives NaN for an infinity, ``conds2`` gives NaN) without the
  SVD: LAPACK prints "illegal value" on standard error for one.  ``eigvalsh`` reads only one
  triangle and returns numbers, not an error, for a matrix holding a NaN, so it is never
  given one either.

A batch is measured matrix by matrix by the same LAPACK calls as one matrix alone, so
each figure of a batch is the bit-for-bit equal of the single matrix's.
"""

from __future__ import annotations

import numpy as np


def _eigen_ok(A: np.ndarray) -> np.ndarray:
    """Whether each matrix is finite and exactly symmetric (the batch's leading axes)."""
    return np.all(np.isfinite(A), axis=(-2, -1)) & np.all(A == np.swapaxes(A, -1, -2), axis=(-2, -1))


def _magnitudes(A: np.ndarray) -> np.ndarray:
    """|λ| in ascending order of each finite symmetric matrix of A."""
    return np.sort(np.abs(np.linalg.eigvalsh(A)), axis=-1)


def _singular(A) -> np.ndarray:
    """What ``np.linalg.norm(A, 2)`` does with matrices that are not finite: with a NaN the SVD
    does not converge (``LinAlgError``); with infinities only it gives NaN."""
    if np.isnan(A).any():
        raise np.linalg.LinAlgError("SVD did not converge")
    return np.full(A.shape[:-2], np.nan)


def _measure(A, of_magnitudes, by_svd, not_finite=_singular):
    """``of_magnitudes(|λ| ascending)`` of each finite symmetric matrix, ``by_svd(matrices)`` of
    the other finite ones, ``not_finite(matrices)`` of those holding a NaN or an infinity; a
    float for one matrix, an array for a batch."""
    A = np.asarray(A, dtype=float)
    single = A.ndim == 2
    batch = A[None] if single else A
    ok = _eigen_ok(batch)
    finite = np.all(np.isfinite(batch), axis=(-2, -1))
    out = np.empty(batch.shape[:-2])
    if np.any(ok):
        out[ok] = of_magnitudes(_magnitudes(batch[ok]))
    rest = ~ok & finite
    if np.any(rest):
        out[rest] = by_svd(batch[rest])
    if not np.all(finite):  # LAPACK is never given one: it prints "illegal value" on stderr
        out[~finite] = not_finite(batch[~finite])
    return float(out[0]) if single else out


def norms2(A) -> np.ndarray | float:
    """‖A‖₂ of a matrix (a float), or of each matrix of a batch (an array)."""
    return _measure(A, lambda s: s[..., -1], lambda B: np.linalg.norm(B, 2, axis=(-2, -1)))


def _nan(A) -> np.ndarray:
    """What ``np.linalg.cond`` gives a matrix that is not finite."""
    return np.full(A.shape[:-2], np.nan)


def conds2(A) -> np.ndarray | float:
    """κ₂(A) = σ₁/σₙ of a matrix (a float), or of each matrix of a batch; inf where A is singular.

    A matrix that is not finite gets NaN, as ``np.linalg.cond`` gives it (callers map that
    to inf before using it)."""
    with np.errstate(all="ignore"):
        return _measure(A, lambda s: s[..., -1] / s[..., 0], np.linalg.cond, _nan)
