"""Trap: the coordinate map follows other conventions than the hand model (``crba`` or ``gravity`` fails).

The conventions are searched jointly: every combination of an axis sign flip on any
subset of the coordinates, absolute vs relative angles, zero shifts of k·π/2 per angle,
degrees vs radians (``pendverify.diagnosis.traps.convention_maps``), and the pivot-inertia
fit after the map change, so that two traps at once are named as well as one.

1. Screen (``convention_screen``): every candidate map's M and H at ``SCREEN_STATES``
   states, vectorised, against the hand model's; its residual is the error left over the
   declared map's.
2. Confirm: the candidates whose screen residual is at most ``SCREEN_RESIDUAL``, simplest
   first (fewest traps, then fewest coordinates touched, then smallest residual), are
   tried one by one, at most ``MAX_CONFIRMED``: the URDF seen through the candidate map
   (with the fitted inertias taken about the centres of mass) is put through every
   applicable check on all the diagnosis states.  Its residual is the largest relative
   error of ``crba`` and ``gravity`` after over before.  The first candidate under which
   every check passes, or whose residual is within ``FIT_RESIDUAL``
   (``pendverify.diagnosis.traps.fit``), is the diagnosis.  If that explanation changes no
   map (an inertia about the pivot, nothing else), it is ``inertia.pivot_inertia``'s to
   name, and this trap names nothing.
3. Candidates as simple and as exact as the one named (a mirror-symmetric robot cannot
   tell a flip of one angle from a flip of the other) are confirmed too, at most
   ``MAX_ALTERNATIVES``, and listed with it.

The screen uses the last ``SCREEN_STATES`` diagnosis states, random ones
(``checks.sampling.sample_states`` puts the special states first): at generic angles
no two different maps give the same M and H by accident.  Each candidate's screen residual
is measured on those states alone, a subset of the states the confirmation judges; its
numerator and denominator are maxima over fewer states, so it can differ from the confirmed
residual by the spread of the discrepancy over the states (a factor of a few for these
trigonometric terms) — hence the screen passes ten times ``FIT_RESIDUAL`` and only the
confirmation decides.  A failure that neither ``crba`` nor ``gravity`` shows is not a
convention trap: every one of them changes M or H.

The diagnosis is a ``Finding`` of kind ``convention`` about the whole model (quantity
None), its message the sentence of ``convention_words`` — when the map alone makes every check
pass, with the keys of the model file that declare it (``joints``, ``transform``, ``offset``:
``convention_words.declared_as``); ``details`` holds ``traps`` (the
short names, ``convention_maps``), ``residual``, the map it names (``T``, ``theta0``), the
pivot fit (``links``: link → c_b, +1 the URDF's inertia about the pivot, −1 the hand's
counted twice) and the ``alternatives`` confirmed with it (each with the same fields).
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.traps import convention_words as words
from pendverify.diagnosis.traps.convention_maps import PIVOT, Candidate, candidates, left_out, most_touched
from pendverify.diagnosis.traps.convention_screen import screen
from pendverify.diagnosis.traps.fit import DIAGNOSIS_SEED, EXACT_RESIDUAL, FIT_RESIDUAL
from pendverify.diagnosis.traps.inertia import corrected_system, parallel_axis_terms
from pendverify.robot.coordinates import CoordinateMap

SCREEN_STATES = 4  # random states the screen evaluates every candidate at
SCREEN_RESIDUAL = 10 * FIT_RESIDUAL  # screen residual a candidate must reach to be confirmed
MAX_CONFIRMED = 12  # candidates put through the checks at most, before the one named
MAX_ALTERNATIVES = 3  # equally simple candidates confirmed and listed besides it


def _discrepancy(model, system, states) -> tuple[float, bool]:
    """(largest relative error of crba and gravity, whether every applicable check passes)."""
    quick_names = ("crba", "gravity")
    quick = run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, names=quick_names)
    largest = max(r.error for r in quick)
    if not all(r.passed for r in quick):
        return largest, False
    rest = [n for n in applicable_checks(model, system) if n not in quick_names]  # crba, gravity done
    return largest, all(
        r.passed for r in run_checks("diagnosis", model, system, states, DIAGNOSIS_SEED, rest)
    )


def _links(found, i: int) -> dict[str, int]:
    return {n: int(k) for n, k in zip(found.links, found.coefficients[i], strict=True) if k}


def _traps(c: Candidate, links) -> list[str]:
    return [*c.traps, PIVOT] if links else list(c.traps)


def _confirm(model, system, c: Candidate, links, states, before) -> tuple[float, bool]:
    """(residual, whether every check passes) with the URDF seen through candidate ``c``."""
    cmap = CoordinateMap(c.T, c.theta0, system.cmap.joint_nq)
    corrected = corrected_system(system, links, cmap)
    if corrected is None:  # the correction leaves a body no physical inertia: not an explanation
        return np.inf, False
    after, passes = _discrepancy(model, corrected, states)
    return after / before, passes


def _mr2(system) -> dict[str, float]:
    """{link: m·r², the largest entry of its parallel-axis term at θ = 0}."""
    names, at_zero = parallel_axis_terms(system, np.zeros((1, system.model.nv)))
    return {n: float(np.max(np.abs(k))) for n, k in zip(names, at_zero, strict=True)}


def _sentence(model, system, c: Candidate, links, residual, passes, alternatives) -> str:
    theta0 = system.cmap.theta0
    mr2 = _mr2(system) if links or any(al for _, al in alternatives) else {}
    if len(_traps(c, links)) == 1:
        sentence = words.single(model, c, theta0)
    else:
        sentence = words.joint(model, c, theta0, links, mr2)
    sentence = words.with_fit(sentence, residual, passes)
    if passes and not links:  # the map alone: what to write in the model file
        sentence += f"; {words.declared_as(model, c, theta0)}"
    if alternatives:
        sentence += words.alternatives(model, alternatives, theta0, mr2)
    return sentence


def _revolute(system) -> list[bool]:
    """Per joint coordinate, whether its joint turns (Pinocchio's revolute joint models, bounded or not)."""
    return [
        system.model.joints[j].shortname().startswith("JointModelR") for j in range(1, system.model.njoints)
    ]


def _simplicity(maps, found, i: int) -> tuple:
    """(traps, coordinates and links touched, screen residual, index): the order candidates are tried in."""
    links = _links(found, i)
    return (len(_traps(maps[i], links)), maps[i].touched + len(links), found.residual[i], i)


def _ranked(maps, found) -> list[int]:
    """The candidates the screen passes, simplest first; the declared map only with a pivot fit."""
    passed = [i for i in range(len(maps)) if found.residual[i] <= SCREEN_RESIDUAL]
    passed = [i for i in passed if i > 0 or np.any(found.coefficients[0])]
    return sorted(passed, key=lambda i: _simplicity(maps, found, i))


def _alternatives(model, system, maps, found, order, named: int, states, before):
    """The candidates as simple as ``named`` under which every check passes as exactly (module docstring)."""
    out = []
    for j in order[order.index(named) + 1 :]:
        if (
            len(out) == MAX_ALTERNATIVES
            or _simplicity(maps, found, j)[:2] > _simplicity(maps, found, named)[:2]
        ):
            break
        if found.residual[j] > EXACT_RESIDUAL or not maps[j].traps:
            continue
        links = _links(found, j)
        residual, passes = _confirm(model, system, maps[j], links, states, before)
        if passes and residual <= EXACT_RESIDUAL:
            out.append((maps[j], links))
    return out


def coordinate_conventions(model, system, failing, states, unsearched: list | None = None) -> Finding | None:
    """The simplest combination of convention traps that explains the failure, confirmed by every
    check on ``states`` (module docstring), or None.  What the search's bounds leave out
    (``convention_maps.left_out``, the candidates the screen did not fit) is added to ``unsearched``."""
    if not {"crba", "gravity"} & set(failing):
        return None
    maps = candidates(model, system.cmap.T, system.cmap.theta0, _revolute(system))
    found = screen(model, system, maps, states[-SCREEN_STATES:], SCREEN_RESIDUAL)
    if unsearched is not None:
        unsearched += [w for w in (left_out(model, most_touched(model, system.cmap.theta0)),) if w]
        if found is not None and found.unfitted:
            unsearched.append(
                f"the pivot-inertia fit of {found.unfitted} coordinate convention maps whose H agrees"
            )
    if found is None or not found.before > 0:
        return None
    order = _ranked(maps, found)
    before, _ = _discrepancy(model, system, states)
    if not order or not before > 0:
        return None
    for i in order[:MAX_CONFIRMED]:
        c, links = maps[i], _links(found, i)
        residual, passes = _confirm(model, system, c, links, states, before)
        if passes or residual <= FIT_RESIDUAL:
            break
    else:
        return None
    if not c.traps:
        return None  # an inertia about the pivot alone: inertia.pivot_inertia names it
    exact = passes and residual <= EXACT_RESIDUAL
    alternatives = _alternatives(model, system, maps, found, order, i, states, before) if exact else []
    details = {
        "traps": _traps(c, links),
        "residual": float(residual),
        "exact": bool(exact),
        "T": c.T.tolist(),
        "theta0": c.theta0.tolist(),
        "links": links,
        "alternatives": [
            {"traps": _traps(a, al), "T": a.T.tolist(), "theta0": a.theta0.tolist(), "links": al}
            for a, al in alternatives
        ],
    }
    message = _sentence(model, system, c, links, residual, passes, alternatives)
    return Finding(kind="convention", message=message, details=details)
