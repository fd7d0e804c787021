"""Trap: the coordinate map follows another convention than the hand model (any check fails).

The coordinate map q = T (θ − θ0) is changed as each trap would change it,
and the change is adopted when every check then passes on a small state set:
absolute vs relative angles (T → T·A or T·A⁻¹, A the difference matrix of
consecutive angles, θ_rel = A·θ_abs), degrees vs radians (θ0 read as degrees;
angles scaled by π/180), an angle zero measured from the vertical instead of the
horizontal (θ0 shifted by ±π/2, on one angle or on all), and from hanging instead
of upright (±π).  The residual is the largest relative error of ``crba`` and
``gravity`` after the change over the one before; a change that leaves at most
``FIT_RESIDUAL`` of it is named even when some check still fails.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.traps.fit import DIAGNOSIS_SEED, EXACT_RESIDUAL, FIT_RESIDUAL, fmt
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.system import PinocchioSystem


def _with_map(system: PinocchioSystem, T, theta0) -> PinocchioSystem:
    cmap = CoordinateMap(np.asarray(T, float), np.asarray(theta0, float), system.cmap.joint_nq)
    return system.with_map(cmap)


def _discrepancy(model, system, states) -> tuple[float, bool]:
    """(largest relative error of crba and gravity, whether every applicable check passes)."""
    quick_names = ("crba", "gravity")
    quick = run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, names=quick_names)
    largest = max(r.max_error for r in quick)
    if not all(r.passed for r in quick):
        return largest, False
    rest = [n for n in applicable_checks(model, system) if n not in quick_names]  # crba, gravity done
    return largest, all(
        r.passed for r in run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, rest)
    )


def _difference_matrix(model) -> np.ndarray:
    """A with θ_rel = A θ_abs over the angular coordinates, in order."""
    A = np.eye(model.nv)
    angular = [i for i, a in enumerate(model.angular) if a]
    for prev, cur in itertools.pairwise(angular):
        A[cur, prev] = -1.0
    return A


def _map_candidates(model, system):
    """(sentence, T', θ0') for each convention trap."""
    T, theta0 = system.cmap.T, system.cmap.theta0
    angular = np.array(model.angular)
    if angular.sum() >= 2:
        A = _difference_matrix(model)
        A_inv = np.linalg.inv(A)
        yield (
            "absolute vs relative angles: the hand model's angles are absolute (all from one reference) "
            "where the coordinate map takes them as relative (each from the previous link); with "
            f"θ_rel = A·θ_abs, T → T·A = {(T @ A).tolist()}, every check passes",
            T @ A,
            A_inv @ theta0,
        )
        yield (
            "absolute vs relative angles: the hand model's angles are relative (each from the previous "
            "link) where the coordinate map takes them as absolute; with T → T·A⁻¹ = "
            f"{(T @ A_inv).tolist()}, every check passes",
            T @ A_inv,
            A @ theta0,
        )
    deg = math.pi / 180
    if np.any(theta0[angular] != 0):
        fixed = np.where(angular, theta0 * deg, theta0)
        yield (
            f"degrees vs radians: the offsets θ0 = {fmt(theta0[angular])} look like degrees; read as "
            f"degrees, θ0 = {fmt(fixed[angular])} rad, and every check passes "
            "(angles are radians throughout)",
            T,
            fixed,
        )
        nonzero = [i for i in np.flatnonzero(angular) if theta0[i] != 0]
        for i in nonzero if len(nonzero) >= 2 else ():
            one = theta0.copy()
            one[i] = theta0[i] * deg
            yield (
                f"degrees vs radians: the offset of {model.coordinates[i]}, {theta0[i]:.6g}, is in degrees "
                f"while the others are in radians; read as {one[i]:.6g} rad, every check passes",
                T,
                one,
            )
    S = np.diag(np.where(angular, deg, 1.0))
    yield (
        "degrees vs radians: the hand model's angles behave as degrees; scaled by π/180 every check passes",
        T @ S,
        np.linalg.inv(S) @ theta0,
    )
    subsets = [[i] for i in np.flatnonzero(angular)]
    if angular.sum() >= 2:
        subsets.append(list(np.flatnonzero(angular)))
    for shift, what in ((math.pi / 2, "vertical vs horizontal zero"), (math.pi, "upright vs hanging zero")):
        for subset in subsets:
            for sign in (1.0, -1.0):
                offset = np.zeros(model.nv)
                offset[subset] = sign * shift
                which = ", ".join(model.coordinates[i] for i in subset)
                plane = (
                    "measured from the vertical where the map measures from the horizontal, or the reverse"
                    if shift < 3
                    else "measured from hanging where the map measures from upright, or the reverse"
                )
                yield (
                    f"{what}: {which} {'is' if len(subset) == 1 else 'are'} {plane}; with θ0 shifted by "
                    f"{'+' if sign > 0 else '−'}{'π/2' if shift < 3 else 'π'} on {which} every check passes",
                    T,
                    theta0 + offset,
                )


def coordinate_conventions(model, system, failing, states) -> str | None:
    before, _ = _discrepancy(model, system, states)
    if not before > 0:
        return None
    for sentence, T, theta0 in _map_candidates(model, system):
        if abs(np.linalg.det(T)) < 1e-12:
            continue
        after, every_check_passes = _discrepancy(model, _with_map(system, T, theta0), states)
        residual = after / before
        if every_check_passes:
            fit = "an exact fit" if residual <= EXACT_RESIDUAL else "a fit within the tolerances"
            return f"{sentence} ({fit}: residual {residual:.2g} of the discrepancy)"
        if residual <= FIT_RESIDUAL:
            return (
                sentence.replace("every check passes", f"all but {residual:.2g} of the discrepancy goes")
                + "; a smaller difference remains as well"
            )
    return None
