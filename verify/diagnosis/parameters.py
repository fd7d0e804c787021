"""The inertial parameters a hand model implies, in words: is it this robot with other masses, and which?

``pendverify.diagnosis.implied`` fits the hand model's M, C·q̇ and H by the URDF tree's joint
torque regressor over the identifiable combinations of its inertial parameters;
``pendverify.diagnosis.hypotheses`` explains the difference from the URDF's by physical
changes per link.  Here the result becomes findings: one ``parameters`` finding per changed
parameter of the sparsest explanation (or one listing the combinations that differ), or one
``structural`` finding when no parameters reproduce the equations.

Structural differences
----------------------
When no parameters reproduce the rows, each quantity (M, C·q̇, H) is fitted on its own and
the pairs together, to say which are this robot's for some parameters; and entries are left
out, an irreducible set (``ImpliedParameters.unexplained``), until parameters reproduce the
rest: every sentence of the ``structural`` finding is such a fit, within ``tolerance`` of its
own rows.  Rows the hand model gives no finite value for are left out (the checks report them).
"""

from __future__ import annotations

import itertools

import numpy as np
import pinocchio as pin

from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.hypotheses import Explanation, Hypothesis, all_hypotheses, explanations
from pendverify.diagnosis.implied import AXES, COMPONENTS, ImpliedParameters, implied_parameters
from pendverify.diagnosis.traps.inertia import sides

#: the most work of the fit, R·P² for P parameters and R rows (a QR's): measured, a fit of 100
#: parameters to 7 430 rows (R·P² = 7.4e7, a 10-link chain at 60 states) takes 0.4 s and the
#: structural finding's fits after it 0.8 s more on one core of an idle 2-core machine; a
#: 3-degree-of-freedom model is 8e5.  Beyond the bound the step fits nothing and says so.
MAX_FIT_WORK = 1e8
#: the most groups of hypotheses tried (singles and pairs), ~0.3 ms each (measured: the 4 005 of a
#: 6-link chain's 90 hypotheses in 1.3 s); a 3-degree-of-freedom model has 1 035.  Beyond it only
#: single hypotheses are tried.
MAX_GROUPS = 5000


# --- the findings ------------------------------------------------------------------------------
def _distinct(a: float, b: float) -> tuple[str, str]:
    """a and b with six significant digits, or as many more as it takes to tell them apart."""
    for digits in range(6, 18):
        x, y = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if x != y:
            break
    return x, y


def _values(h: Hypothesis, x: float, model: pin.Model):
    """(model value, URDF value) of the parameter a hypothesis changes: floats, or I_c (3×3)."""
    body = model.inertias[h.joint + 1]
    m, c, I_c = body.mass, np.array(body.lever), np.array(body.inertia)
    if h.parameter == "mass":
        return m + x, m
    if h.parameter == "first moment":
        a = AXES.index(h.label)
        return m * c[a] + x, m * c[a]
    if h.parameter == "centre of mass":
        a = AXES.index(h.label)
        return c[a] + x, c[a]
    if h.parameter == "inertia about the centre of mass":
        _, i, j = next(comp for comp in COMPONENTS if comp[0] == h.label)
        return I_c[i, j] + x, I_c[i, j]
    sign = 1.0 if h.label == "+" else -1.0
    return I_c + sign * (body.matrix()[3:, 3:] - I_c), I_c


def _phrase(h: Hypothesis, model_value, urdf_value, model: pin.Model) -> str:
    """The change in words, as "your equations are this URDF with ..." continues.  An inertia about
    the pivot names both sides it may be wrong on, or the hand model's alone when the URDF rules
    the other out (``pendverify.diagnosis.traps.inertia.sides``)."""
    body = model.inertias[h.joint + 1]
    if h.parameter == "inertia about the pivot":
        c = np.array(body.lever)
        term = f"{body.mass * float(c @ c):.6g} kg·m²"
        larger = h.label == "+"  # the model's inertia is the URDF's plus m·r²
        return (
            f"{h.link}'s inertia {'larger' if larger else 'smaller'} than the URDF's by the parallel-axis "
            f"term m·|c|² = {term}: {sides(model, h.joint + 1, -1 if larger else 1)}"
        )
    ours, theirs = _distinct(model_value, urdf_value)
    if h.parameter == "mass":
        return f"{h.link}'s mass {ours} kg instead of {theirs} kg"
    if h.parameter == "first moment":
        at = f"{model_value / body.mass:.6g} m" if body.mass else "undefined"
        return (
            f"{h.link}'s first moment m·c_{h.label} = {ours} kg·m instead of {theirs} kg·m "
            f"(its centre of mass at {h.label} = {at}, with its inertia about the joint kept?)"
        )
    if h.parameter == "centre of mass":
        return (
            f"{h.link}'s centre of mass at {h.label} = {ours} m instead of {theirs} m "
            "(in its joint frame; mass and inertia about the centre of mass kept)"
        )
    return f"{h.link}'s inertia about its centre of mass I_{h.label} = {ours} kg·m² instead of {theirs} kg·m²"


def _listed(value):
    return np.asarray(value).tolist() if np.ndim(value) else float(value)


def _combinations(implied: ImpliedParameters) -> str:
    """The identifiable combinations that differ, in words."""
    words = []
    for c in implied.combinations:
        if c.differs:
            ours, theirs = _distinct(c.model_value, c.urdf_value)
            words.append(f"{c.name} = {ours} instead of {theirs} {c.unit}")
    return "; ".join(words)


def _findings(found: list[Explanation], implied: ImpliedParameters, model: pin.Model) -> list[Finding]:
    """One finding per changed parameter of each explanation found (several: they are alternatives)."""
    out = []
    for explanation in found:
        changes = [
            (h, *_values(h, x, model), rounding)
            for h, x, rounding in zip(
                explanation.hypotheses, explanation.values, explanation.roundings, strict=True
            )
        ]
        phrases = [_phrase(h, ours, theirs, model) for h, ours, theirs, _ in changes]
        sentence = "your equations are this URDF with " + " and ".join(phrases)
        if len(found) > 1:
            sentence += (
                f" — one of {len(found)} explanations your M, C·q̇ and H cannot tell apart: they fix "
                f"only {_combinations(implied)} (I about each joint's origin)"
            )
        for h, ours, theirs, rounding in changes:
            details = {
                "link": h.link,
                "parameter": h.parameter,
                "model_value": _listed(ours),
                "urdf_value": _listed(theirs),
                "rounding": rounding,
                "residual": explanation.residual,
            }
            if h.parameter in ("first moment", "centre of mass"):
                details["axis"] = h.label
            elif h.parameter == "inertia about the centre of mass":
                details["component"] = h.label
            if len(found) > 1:
                details["alternatives"] = len(found)
            out.append(Finding("parameters", sentence, details=details))
    return out


def _combinations_finding(implied: ImpliedParameters) -> Finding:
    differ = [c for c in implied.combinations if c.differs]
    links = sorted({link for c in differ for _, link, _ in c.terms}, key=implied.links.index)
    return Finding(
        "parameters",
        "your equations are this robot with other inertial parameters, but no one or two changes of "
        "a link's mass, centre of mass or inertia explain them; the identifiable combinations that "
        f"differ (I about each joint's origin): {_combinations(implied)}",
        details={
            "link": links,
            "parameter": "identifiable combinations",
            "combinations": [c.name for c in differ],
            "model_value": [c.model_value for c in differ],
            "urdf_value": [c.urdf_value for c in differ],
            "rounding": [c.rounding for c in differ],
            "residual": implied.residual,
        },
    )


def _written(label: str, model) -> str:
    """A row's entry or quantity (``H[2]``, ``H``) in the model's own name of the quantity (``G[2]``)."""
    quantity, bracket, rest = label.partition("[")
    return model.written_name(quantity) + bracket + rest


def _structural_finding(implied: ImpliedParameters, model) -> Finding:
    """No parameters reproduce all rows: which quantities are this robot's on their own, which entries
    not; named in the model's own names of the quantities (``ClosedFormModel.written_names``)."""
    quantities = implied.quantities
    alone = {q: implied.fits(implied.rows_of(q)) for q in quantities}
    not_alone = [q for q in quantities if not alone[q]]
    if not_alone:
        what = " and ".join(_written(q, model) for q in not_alone)
        where = (
            f"{what} on its own is" if len(not_alone) == 1 else f"{what} are, each on its own,"
        ) + " not this robot's for any inertial parameters"
    else:
        together = [
            f"{_written(a, model)} and {_written(b, model)}"
            for a, b in itertools.combinations(quantities, 2)
            if implied.fits(implied.rows_of(a, b))
        ]
        named = ", ".join(_written(q, model) for q in quantities)
        where = f"{named} are each this robot's with some inertial parameters, but not all with the same ones"
        if together:
            where += f" ({'; '.join(together)} together are)"
    entries = implied.unexplained
    left = ", ".join(_written(e, model) for e in entries)
    relative = implied.residual / float(np.linalg.norm(implied.rows.b))
    return Finding(
        "structural",
        "no mass distribution of this robot produces your equations: the difference is structural: "
        f"{where}; leaving out {left}, parameters reproduce the rest "
        f"(relative residual of the best fit to all of them {relative:.3g})",
        details={"residual": relative, "entries": entries, "not_alone": not_alone},
    )


def _fit_work(batch) -> tuple[int, int]:
    """(rows, parameters) of the fit: n² + 2n rows per state (M, C·q̇, H), ten parameters per body."""
    n = batch.model.nv
    return len(batch) * (n * n + 2 * n), 10 * (batch.system.model.njoints - 1)


def identify_parameters(batch, unsearched: list | None = None) -> list[Finding]:
    """Whether the hand model's M, C·q̇, H are the URDF tree's with other inertial parameters, and which.

    [] when the URDF's own parameters reproduce them; one ``structural`` finding when no
    parameters do; otherwise one ``parameters`` finding per changed parameter of the
    sparsest explanation (module docstring), or one listing the combinations that differ; [] for
    a model that gives q̈ alone (no M, C·q̇, H to compare).

    Bounded by its work, counted before it starts: a fit of P parameters to R rows costs R·P²
    (its QR); beyond ``MAX_FIT_WORK`` nothing is fitted.  Pairs of hypotheses are tried only while
    the groups tried (singles and pairs) stay within ``MAX_GROUPS``.  What is left out is added to
    ``unsearched``, in words.
    """
    if not batch.model.has_mass_matrix:
        return []
    rows, parameters = _fit_work(batch)
    if rows * parameters**2 > MAX_FIT_WORK:
        if unsearched is not None:
            unsearched.append(
                f"the inertial parameters (a fit of {parameters} parameters to {rows} rows, beyond the "
                f"bound of {MAX_FIT_WORK:.0e} on its work)"
            )
        return []
    with np.errstate(all="ignore"):
        implied = implied_parameters(batch)
        if implied.agrees:
            return []
        if not implied.exact:
            return [_structural_finding(implied, batch.model)]
        count = len(all_hypotheses(implied, batch.system.model))
        pairs = count * (count - 1) // 2
        most = 2 if count + pairs <= MAX_GROUPS else 1
        found = explanations(implied, batch.system.model, most)
    if not found and most < 2 and unsearched is not None:
        unsearched.append(f"pairs of changes of the inertial parameters ({pairs} pairs, beyond {MAX_GROUPS})")
    if not found:
        return [_combinations_finding(implied)]
    return _findings(found, implied, batch.system.model)
