"""A convention diagnosis in words: the traps a candidate map names, its map and how well it fits.

One trap alone keeps the sentence each trap has always had (``single``); two or more are
named together, each in a clause, followed by the map they lead to, T' and θ0', and the
inertias the pivot fit takes about the centres of mass (``joint``).  Every sentence says
"every check passes" (each check re-run on every diagnosis state with that map), and
``with_fit`` adds how well: an exact fit at rounding level, a fit within the tolerances, or,
when some check still fails, the part of the discrepancy that goes.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.source_file import where
from pendverify.diagnosis.traps.convention_maps import (
    ABSOLUTE_RELATIVE,
    DEG,
    DEGREES,
    HALF,
    ORDER,
    PIVOT,
    QUARTER,
    SIGN,
    Candidate,
    difference_matrix,
)
from pendverify.diagnosis.traps.fit import EXACT_RESIDUAL, fmt

PASSES = "every check passes"
_SHIFT_WORDS = {1: "+π/2", 2: "+π", 3: "−π/2"}
_COUNT = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six"}


def _names(model, indices) -> str:
    return ", ".join(model.coordinates[i] for i in indices)


def _shift_phrase(model, shifts) -> str:
    """ "+π/2 on theta1" or "+π/2 on theta1 and −π/2 on theta2": the shifts of θ0 by coordinate."""
    groups = {}
    for i, k in enumerate(shifts):
        if k:
            groups.setdefault(k, []).append(i)
    return " and ".join(f"{_SHIFT_WORDS[k]} on {_names(model, idx)}" for k, idx in groups.items())


def _zero_clause(model, c: Candidate, half: bool) -> str:
    idx = [i for i, k in enumerate(c.shifts) if (k == 2) == half and k]
    which, verb = _names(model, idx), "is" if len(idx) == 1 else "are"
    if half:
        return (
            f"{HALF}: {which} {verb} measured from hanging where the map measures from upright, "
            "or the reverse"
        )
    return (
        f"{QUARTER}: {which} {verb} measured from the vertical where the map measures from the horizontal, "
        "or the reverse"
    )


def _degrees_clause(model, c: Candidate, theta0) -> str:
    if c.angles_in_degrees:
        return f"{DEGREES}: the hand model's angles behave as degrees"
    nonzero = [i for i, a in enumerate(model.angular) if a and theta0[i] != 0]
    if len(c.offsets_in_degrees) == len(nonzero):
        return f"{DEGREES}: the offsets θ0 = {fmt(theta0[nonzero])} are degrees"
    (i,) = c.offsets_in_degrees
    return f"{DEGREES}: the offset of {model.coordinates[i]}, {theta0[i]:.6g}, is in degrees"


def _relative_clause(c: Candidate) -> str:
    if c.relative > 0:
        return (
            f"{ABSOLUTE_RELATIVE}: the hand model's angles are absolute where the coordinate map takes them "
            "as relative"
        )
    return (
        f"{ABSOLUTE_RELATIVE}: the hand model's angles are relative where the coordinate map takes them "
        "as absolute"
    )


def _order_matters(model, c: Candidate) -> bool:
    """Whether flipping before or after the change between absolute and relative angles differ."""
    if not c.relative:
        return False
    A = difference_matrix(model)
    S = np.diag([-1.0 if i in c.flips else 1.0 for i in range(model.nv)])
    return not np.array_equal(S @ A, A @ S)


def _sign_clause(model, c: Candidate) -> str:
    verb = "turns" if len(c.flips) == 1 else "turn"
    where = ""
    if _order_matters(model, c):
        where = (
            " (in the hand's own coordinates, before the change between absolute and relative angles)"
            if c.flip_first
            else " (in the map's coordinates, after the change between absolute and relative angles)"
        )
    return f"{SIGN}: {_names(model, c.flips)} {verb} the other way round{where}"


def _order_clause(model, c: Candidate) -> str:
    joints = model.urdf_joints or [f"joint {i + 1}" for i in range(model.nv)]
    moved = sorted((k, i) for i, k in enumerate(c.order) if i != k)
    pairs = ", ".join(f"{model.coordinates[k]} is {joints[i]}'s coordinate" for k, i in moved)
    return f"{ORDER}: the hand model's coordinates are the joints in another order than the map's ({pairs})"


#: a coordinate-map key of a model file, by the form the model is written in: the key of a text or
#: LaTeX file's [urdf] table, of a declaration's "urdf" dict, the class attribute of a Python class
_MAP_KEYS = {
    "joints": ("joints", "urdf_joints"),
    "transform": ("transform", "joint_transform"),
    "offset": ("offset", "joint_offset"),
}


def _number(x: float):
    """An entry of a map as a file would hold it: an integer where it is one."""
    x = float(x)
    return round(x) if abs(x - round(x)) <= 1e-12 else float(f"{x:.12g}")


def declared_as(model, c: Candidate, theta0) -> str:
    """Where and how the model file declares the map ``c`` leads to: the keys the user edits
    (``joints`` reordered for joints listed in another order under an identity map, else
    ``transform`` and, where it changes, ``offset``), in the model's own form."""
    cls = type(model)
    spec = getattr(cls, "text_spec", None)
    declared = np.eye(model.nv) if model.joint_transform is None else model.joint_transform
    identity = np.array_equal(np.asarray(declared, float), np.eye(model.nv))
    values = {}
    if c.order and identity and not np.any(theta0) and model.urdf_joints:
        values["joints"] = [model.urdf_joints[c.order.index(k)] for k in range(model.nv)]
    else:
        values["transform"] = [[_number(x) for x in row] for row in c.T]
        if not np.allclose(c.theta0, theta0, rtol=0, atol=1e-12):
            values["offset"] = [_number(x) for x in c.theta0]
    if spec is None:
        keys = [f"{cls.__name__}.{_MAP_KEYS[k][1]} = {v}" for k, v in values.items()]
        return f"declare it as {' and '.join(keys)} in {where(cls)}"
    if str(spec.path).endswith(".toml"):
        keys = [f"{k} = {v}" for k, v in values.items()]
        return f"declare it as {' and '.join(keys)} under [urdf] in {spec.path}"
    keys = [f'DECLARATION["urdf"]["{k}"] = {v}' for k, v in values.items()]
    return f"declare it as {' and '.join(keys)} in {spec.path}"


def pivot_clause(links: dict[str, int], mr2: dict[str, float]) -> str:
    """The pivot fit's clause: which links' inertias are about the pivot, or counted twice; each with the
    other side M cannot tell from it (``pendverify.diagnosis.traps.inertia``, "Which side is wrong")."""
    plus = [n for n, k in links.items() if k > 0]
    minus = [n for n, k in links.items() if k < 0]
    parts = []
    if plus:
        parts.append(
            f"the URDF's inertia of {', '.join(plus)} is about the pivot instead of the centre of mass, "
            "or your M misses the parallel-axis term "
            f"(m·r² = {', '.join(f'{mr2[n]:.6g} kg·m²' for n in plus)})"
        )
    if minus:
        parts.append(
            f"the hand model adds m·r² to the inertia of {', '.join(minus)}, already about the pivot, "
            "or the URDF's <inertia> is m·r² short "
            f"(m·r² = {', '.join(f'{mr2[n]:.6g} kg·m²' for n in minus)})"
        )
    return f"{PIVOT}: " + " and ".join(parts)


def single(model, c: Candidate, theta0) -> str:
    """The sentence of one trap alone (its words as they have always been), before the fit."""
    (trap,) = c.traps
    angular = np.array(model.angular, dtype=bool)
    if trap == ABSOLUTE_RELATIVE and c.relative > 0:
        sentence = (
            "absolute vs relative angles: the hand model's angles are absolute (all from one reference) "
            "where the coordinate map takes them as relative (each from the previous link); with "
            f"θ_rel = A·θ_abs, T → T·A = {c.T.tolist()}, {PASSES}"
        )
    elif trap == ABSOLUTE_RELATIVE:
        sentence = (
            "absolute vs relative angles: the hand model's angles are relative (each from the previous "
            "link) where the coordinate map takes them as absolute; with T → T·A⁻¹ = "
            f"{c.T.tolist()}, {PASSES}"
        )
    elif trap == DEGREES and c.angles_in_degrees:
        sentence = f"degrees vs radians: the hand model's angles behave as degrees; scaled by π/180 {PASSES}"
    elif trap == DEGREES:
        clause = _degrees_clause(model, c, theta0)
        if clause.endswith("are degrees"):
            fixed = np.where(angular, theta0 * DEG, theta0)
            sentence = (
                f"degrees vs radians: the offsets θ0 = {fmt(theta0[angular])} look like degrees; read as "
                f"degrees, θ0 = {fmt(fixed[angular])} rad, and {PASSES} (angles are radians throughout)"
            )
        else:
            (i,) = c.offsets_in_degrees
            sentence = (
                f"degrees vs radians: the offset of {model.coordinates[i]}, {theta0[i]:.6g}, is in degrees "
                f"while the others are in radians; read as {theta0[i] * DEG:.6g} rad, {PASSES}"
            )
    elif trap == SIGN:
        sentence = f"{_sign_clause(model, c)}; with T → T·S = {c.T.tolist()}, {PASSES}"
    elif trap == ORDER:
        sentence = f"{_order_clause(model, c)}; with the joints in that order {PASSES}"
    else:  # a zero shift
        phrase = _shift_phrase(model, c.shifts)
        sentence = f"{_zero_clause(model, c, trap == HALF)}; with θ0 shifted by {phrase} {PASSES}"
    states_theta0 = trap in (QUARTER, HALF) or (trap == DEGREES and not c.angles_in_degrees)
    if states_theta0 or np.array_equal(c.theta0, theta0):
        return sentence
    if f", {PASSES}" in sentence:
        return sentence.replace(f", {PASSES}", f" and θ0 → {fmt(c.theta0)}, {PASSES}")
    return sentence.replace(f" {PASSES}", f", with θ0 → {fmt(c.theta0)}, {PASSES}")


def clauses(model, c: Candidate, theta0, links: dict[str, int], mr2: dict[str, float]) -> list[str]:
    """One clause per trap of ``c`` (and the pivot fit's ``links``), in the order of ``c.traps``."""
    clauses = []
    for trap in c.traps:
        if trap == ORDER:
            clauses.append(_order_clause(model, c))
        elif trap == SIGN:
            clauses.append(_sign_clause(model, c))
        elif trap == ABSOLUTE_RELATIVE:
            clauses.append(_relative_clause(c))
        elif trap == DEGREES:
            clauses.append(_degrees_clause(model, c, theta0))
        else:
            clauses.append(_zero_clause(model, c, trap == HALF))
    if links:
        clauses.append(pivot_clause(links, mr2))
    return clauses


def map_words(c: Candidate) -> str:
    """ "T → T·S·A = [[…]] and θ0 → (…)": the map the traps lead to."""
    T_words = f"T → T·{c.factors} = {np.round(c.T, 12).tolist()}" if c.factors else "T as declared"
    return f"{T_words} and θ0 → {fmt(c.theta0)}"


def joint(model, c: Candidate, theta0, links: dict[str, int], mr2: dict[str, float]) -> str:
    """The sentence of several traps at once, before the fit."""
    named = clauses(model, c, theta0, links, mr2)
    count = len(named)
    inertia = ", the inertias taken about the centres of mass" if links else ""
    return (
        f"{_COUNT.get(count, str(count))} convention traps at once — {'; '.join(named)}: with {map_words(c)}"
        f"{inertia}, {PASSES}"
    )


def alternatives(model, found: list[tuple[Candidate, dict[str, int]]], theta0, mr2) -> str:
    """The equally simple maps under which every check passes exactly as well, one clause each."""
    return "; as simple and as exact, so that the URDF cannot tell them apart: " + "; ".join(
        f"{', '.join(clauses(model, c, theta0, links, mr2))} (with {map_words(c)})" for c, links in found
    )


def with_fit(sentence: str, residual: float, passes: bool) -> str:
    """The sentence with how well it fits (module docstring)."""
    if passes:
        fit = "an exact fit" if residual <= EXACT_RESIDUAL else "a fit within the tolerances"
        return f"{sentence} ({fit}: residual {residual:.2g} of the discrepancy)"
    return (
        sentence.replace(PASSES, f"all but {residual:.2g} of the discrepancy goes")
        + "; a smaller difference remains as well"
    )
