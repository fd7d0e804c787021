"""The physical changes that may explain what a hand model implies: per link, a mass, a centre of
mass, an inertia, an inertia about the pivot (``pendverify.diagnosis.implied`` gives the fit).

Hypotheses
----------
Δπ = π_model − π_urdf is explained per link by physical changes, each Δπ(x) = x·u + x²·w in
its unknown x (built with ``pin.Inertia`` from the URDF body's m, c, I_c):

* ``mass``: m → m + x, c and I_c kept (linear: u = [1, c, |c|²𝟙 − ccᵀ]);
* ``first moment`` along an axis: m·c_a → m·c_a + x, m and the inertia about the joint kept;
* ``centre of mass`` along an axis: c_a → c_a + x, m and I_c kept (quadratic: I = I_c + m(...));
* ``inertia about the centre of mass``, one component: I_c,k → I_c,k + x;
* ``inertia about the pivot``: I_c → I_c ± m(|c|²𝟙 − ccᵀ), no unknown (+: the model's I_c is
  the URDF's inertia about the joint; −: the URDF's I_c is the model's inertia about the joint).

A hypothesis whose direction lies in the null space (its data-space image within the rank
tolerance of zero) says nothing and is skipped.  Single hypotheses are tried first, then
pairs; the unknowns are solved by Gauss–Newton from the linear fit (exact for the linear
ones), and an explanation is accepted only when Y·(π_urdf + Δπ(x)) reproduces the hand
model's rows within ``tolerance``; a solved value's rounding (a finding's ``rounding``) is
‖row of J⁺‖·``tolerance``, J the image of ∂Δπ/∂x at the solution.  Among the accepted,
the fewest hypotheses, then the fewest unknowns win; when several remain the equations
cannot tell them apart and every one is reported, saying so and naming the combinations the
equations fix.  An explanation
without unknowns (an inertia about the pivot) predicts the difference rather than fitting it,
so it is preferred to a one-unknown one that also fits (any change of I_xx fits what m·r² on
I_xx does).  When no one or two hypotheses fit, the combinations that differ beyond their
rounding are listed instead.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pendverify.checks.trust import EPS
from pendverify.diagnosis.implied import (
    AXES,
    COMPONENTS,
    GAUSS_NEWTON_STEPS,
    ImpliedParameters,
)


# --- the physical hypotheses -------------------------------------------------------------------
@dataclass(frozen=True)
class Hypothesis:
    """One physical change of one link: Δπ(x) = x·u + x²·w (u alone when it has no unknown)."""

    joint: int  # 0-based joint index (the link's block of ten parameters)
    link: str
    parameter: str  # the Finding's "parameter"
    label: str  # axis or component ("y", "xx"), sign ("+", "−") or ""
    unknowns: int
    u: np.ndarray  # (10,)
    w: np.ndarray  # (10,)


def _dynamic(inertia: pin.Inertia) -> np.ndarray:
    return inertia.toDynamicParameters()


def _quadratic(f) -> tuple[np.ndarray, np.ndarray]:
    """u, w of a change Δπ(x) quadratic in x (exact: from x = ±1)."""
    plus, minus = f(1.0), f(-1.0)
    return (plus - minus) / 2.0, (plus + minus) / 2.0


def link_hypotheses(model: pin.Model, joint: int, link: str) -> list[Hypothesis]:
    """Every hypothesis of one link (module docstring), built from its URDF body with ``pin.Inertia``."""
    body = model.inertias[joint + 1]
    m, c, I_c = body.mass, np.array(body.lever), np.array(body.inertia)
    pi0 = _dynamic(body)
    out = []

    def add(parameter, label, f, unknowns=1):
        u, w = _quadratic(f) if unknowns else (f(), np.zeros(10))
        out.append(Hypothesis(joint, link, parameter, label, unknowns, u, w))

    add("mass", "", lambda x: _dynamic(pin.Inertia(m + x, c, I_c)) - pi0)
    for a, axis in enumerate(AXES):
        add("first moment", axis, lambda x, a=a: x * np.eye(10)[1 + a])
    for a, axis in enumerate(AXES):
        add("centre of mass", axis, lambda x, a=a: _dynamic(pin.Inertia(m, c + x * np.eye(3)[a], I_c)) - pi0)
    for k, (name, _, _) in enumerate(COMPONENTS):
        add("inertia about the centre of mass", name, lambda x, k=k: x * np.eye(10)[4 + k])
    shift = body.matrix()[3:, 3:] - I_c  # m(|c|²𝟙 − ccᵀ): the joint-origin inertia less I_c
    if np.any(shift != 0):
        for sign, label in ((1.0, "+"), (-1.0, "−")):
            add(
                "inertia about the pivot",
                label,
                lambda s=sign: s * _dynamic(pin.Inertia(0.0, np.zeros(3), shift)),
                0,
            )
    return out


@dataclass(frozen=True)
class Explanation:
    """Hypotheses with their solved unknowns, and the residual of π_urdf + Δπ."""

    hypotheses: tuple[Hypothesis, ...]
    values: tuple[float, ...]  # one per hypothesis (0 for one without an unknown)
    residual: float
    #: each value's rounding: ‖row of J⁺‖·tolerance, J the image of ∂Δπ/∂x (0 without an unknown)
    roundings: tuple[float, ...]

    @property
    def unknowns(self) -> int:
        return sum(h.unknowns for h in self.hypotheses)


def _delta(hypotheses, x, P):
    out = np.zeros(P)
    for h, xi in zip(hypotheses, x, strict=True):
        block = h.u * xi + h.w * xi**2 if h.unknowns else h.u
        out[10 * h.joint : 10 * h.joint + 10] += block
    return out


def _directions(hypotheses, x, P):
    """∂Δπ/∂x for the hypotheses with an unknown (P, k)."""
    cols = []
    for h, xi in zip(hypotheses, x, strict=True):
        if h.unknowns:
            col = np.zeros(P)
            col[10 * h.joint : 10 * h.joint + 10] = h.u + 2.0 * xi * h.w
            cols.append(col)
    return np.array(cols).reshape(-1, P).T


def _solve(implied: ImpliedParameters, hypotheses) -> Explanation | None:
    """The hypotheses' unknowns by Gauss–Newton from the linear fit; None when they are not identifiable."""
    phi, target, P = implied.phi, implied.target, implied.phi.shape[1]
    x, rounding = np.zeros(len(hypotheses)), np.zeros(len(hypotheses))
    free = np.array([h.unknowns > 0 for h in hypotheses])
    if free.any():
        D = _directions(hypotheses, x, P)
        A = phi @ D
        # each direction's image against the sum of its parameters' separate images (unit-free)
        separate = implied.norms @ np.abs(D)
        if not np.all(separate > 0):  # moves only parameters that never enter
            return None
        singular = np.linalg.svd(A / separate, compute_uv=False)
        if singular[-1] <= implied.rank_tolerance:  # a direction in the null space, or two alike
            return None
        for _ in range(GAUSS_NEWTON_STEPS):
            r = target - phi @ _delta(hypotheses, x, P)
            J = phi @ _directions(hypotheses, x, P)
            step, *_ = np.linalg.lstsq(J, r, rcond=None)
            x[free] += step
            if np.all(np.abs(step) <= 4 * EPS * np.abs(x[free])):
                break
        # δx = J⁺ δz with ‖δz‖ within the tolerance: each unknown's rounding
        J = phi @ _directions(hypotheses, x, P)
        rounding[free] = np.linalg.norm(np.linalg.pinv(J), axis=1) * implied.tolerance
    misfit = np.linalg.norm(phi @ _delta(hypotheses, x, P) - target)
    residual = float(np.hypot(misfit, implied.residual))
    return Explanation(tuple(hypotheses), tuple(map(float, x)), residual, tuple(map(float, rounding)))


def all_hypotheses(implied: ImpliedParameters, model: pin.Model) -> list[Hypothesis]:
    """Every link's hypotheses, in joint order."""
    return [h for j, link in enumerate(implied.links) for h in link_hypotheses(model, j, link)]


def explanations(implied: ImpliedParameters, model: pin.Model, most: int = 2) -> list[Explanation]:
    """The sparsest explanations of at most ``most`` hypotheses that reproduce the equations to
    rounding (module docstring)."""
    hypotheses = all_hypotheses(implied, model)
    for size in range(1, most + 1):
        found = []
        for group in itertools.combinations(hypotheses, size):
            explanation = _solve(implied, group)
            if explanation is not None and explanation.residual <= implied.tolerance:
                found.append(explanation)
        if found:
            fewest = min(e.unknowns for e in found)
            return [e for e in found if e.unknowns == fewest]
    return []
