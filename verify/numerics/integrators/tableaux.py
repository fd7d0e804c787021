"""The explicit Runge–Kutta methods, as Butcher tableaux (data, run by one stepper).

A tableau with s stages advances x at t by h as

    k_1 = f(t, x),   k_i = f(t + c_i h, x + h Σ_{j<i} a_ij k_j)   (i = 2..s),
    x_new = x + (h / d) Σ_i w_i k_i,

the weights b_i = w_i / d written as whole numbers over one denominator d, the way the
methods are printed (RK4: 1, 2, 2, 1 over 6), so that the common factor h/d is rounded once.
Consistency (order ≥ 1) needs Σ w_i = d, and the internal times are c_i = Σ_j a_ij; both
are checked when a tableau is made.  ``runge_kutta.explicit_rk_step`` runs a tableau on
numpy arrays; ``fixedstep.render_explicit_runs`` writes the same step, compiled, into
each model's generated module.

The stability function of an explicit tableau, R(z) = 1 + z bᵀ (I − zA)⁻¹ 𝟙, is the
growth per step of x' = λx at z = hλ; for RK4 it is 1 + z + z²/2 + z³/6 + z⁴/24 (Hairer
& Wanner, *Solving ODEs II*, §IV.2).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: |c_i − Σ_j a_ij| and |Σ w − d| / d allowed: a tableau's entries are decimals of size ≤ 1 (or
#: whole weights) summed in at most s ≤ 16 terms, each rounding ≤ ε/2 ≈ 1.1e-16, so a consistent
#: tableau is off by < 2e-15; a wrong entry is off by its own size, far above 1e-14
CONSISTENCY_TOL = 1e-14


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge–Kutta method: ``a`` has one row per stage, row i the i entries a_ij (j < i)."""

    name: str
    order: int
    a: tuple[tuple[float, ...], ...]
    c: tuple[float, ...]
    weights: tuple[float, ...]
    denominator: float
    reference: str

    def __post_init__(self) -> None:
        s = len(self.a)
        if len(self.c) != s or len(self.weights) != s:
            raise ValueError(
                f"tableau {self.name}: {s} rows of a, {len(self.c)} c, {len(self.weights)} weights"
            )
        for i, row in enumerate(self.a):
            if len(row) != i:
                raise ValueError(
                    f"tableau {self.name}: row {i + 1} of a has {len(row)} entries, expected {i}"
                )
            if abs(self.c[i] - sum(row)) > CONSISTENCY_TOL:
                raise ValueError(
                    f"tableau {self.name}: c_{i + 1} = {self.c[i]!r} is not the sum of row {i + 1}"
                )
        if abs(sum(self.weights) - self.denominator) > CONSISTENCY_TOL * abs(self.denominator):
            raise ValueError(
                f"tableau {self.name}: weights sum to {sum(self.weights)!r}, not {self.denominator!r}"
            )

    @property
    def stages(self) -> int:
        return len(self.a)

    def stability(self, z):
        """R(z) = 1 + z bᵀ (I − zA)⁻¹ 𝟙 at each z (forward substitution: A is strictly lower)."""
        z = np.asarray(z, dtype=complex)
        g = []  # g_i = 1 + z Σ_j a_ij g_j, the stage values for x = 1
        for row in self.a:
            g.append(1 + z * sum((a * gj for a, gj in zip(row, g, strict=False)), 0 * z))
        return 1 + z * sum(w * gi for w, gi in zip(self.weights, g, strict=True)) / self.denominator


EULER = Tableau(
    "euler",
    order=1,
    a=((),),
    c=(0.0,),
    weights=(1.0,),
    denominator=1.0,
    reference="Euler (1768); Hairer, Nørsett & Wanner, Solving ODEs I, §II.1",
)

RK4 = Tableau(
    "rk4",
    order=4,
    a=((), (0.5,), (0.0, 0.5), (0.0, 0.0, 1.0)),
    c=(0.0, 0.5, 0.5, 1.0),
    weights=(1.0, 2.0, 2.0, 1.0),
    denominator=6.0,
    reference="Kutta (1901), the classical method; Hairer, Nørsett & Wanner, Solving ODEs I, Table II.1.1",
)

#: every explicit tableau by the name scenes, benchmarks and the stress suite use
TABLEAUX = {t.name: t for t in (EULER, RK4)}
