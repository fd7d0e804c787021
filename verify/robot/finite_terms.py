"""A description whose numbers leave double's range in Pinocchio's terms: refused, naming the number.

Pinocchio builds its terms from each body's mass m, centre of mass c and inertia I and from the
joints' placements: the spatial inertias about the world origin (I + m·|c|², carried along the
tree: ``data.oYcrb``), M from them, and the gravity torques m·g·c.  A number of 1e300 in a mass
or an inertia stays finite, but one in a placement squares beyond double's range (1.8e308), and
a mass of 1e300 at a placement of 1e10 does too: then M or a spatial inertia is infinite or NaN
at the neutral configuration already, and nothing can be compared.  ``check_finite_terms``
refuses such a description in one line, naming the number furthest from 1 in orders of
magnitude (the one that overflowed, or its largest factor), the link or joint it belongs to
and the value.  A description whose terms stay finite, however large, is left to the trust
rule (``pendverify.checks.trust``), which refuses states whose rounding would hide an error.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pendverify.errors import PlaceError


def _terms_finite(model: pin.Model) -> bool:
    data = model.createData()
    q = pin.neutral(model)
    with np.errstate(all="ignore"):
        M = pin.crba(model, data, q)
        H = pin.computeGeneralizedGravity(model, data, q)
        spatial = [np.asarray(Y.matrix()) for Y in data.oYcrb]
    return bool(
        np.all(np.isfinite(M)) and np.all(np.isfinite(H)) and all(np.all(np.isfinite(Y)) for Y in spatial)
    )


def _link(model: pin.Model, j: int) -> str:
    """The link joint j moves (its first body frame), or the joint's own name."""
    for frame in model.frames:
        if frame.parentJoint == j and frame.type == pin.FrameType.BODY:
            return f"link '{frame.name}'"
    return f"the body of joint '{model.names[j]}'"


def _numbers(model: pin.Model):
    """(what, value) for every mass, centre-of-mass coordinate, inertia entry and placement offset."""
    for j in range(1, model.njoints):
        body, inertia = _link(model, j), model.inertias[j]
        yield f"{body} mass", float(inertia.mass)
        yield from ((f"{body} centre of mass", float(x)) for x in np.ravel(inertia.lever))
        yield from ((f"{body} inertia", float(x)) for x in np.ravel(inertia.inertia))
        placement = model.jointPlacements[j].translation
        yield from ((f"joint '{model.names[j]}' origin", float(x)) for x in np.ravel(placement))


def check_finite_terms(model: pin.Model, source: str) -> None:
    """Refuse (``PlaceError``) a description whose terms at the neutral configuration are not finite."""
    if _terms_finite(model):
        return
    candidates = [(what, x) for what, x in _numbers(model) if x != 0 and math.isfinite(x)]
    if not candidates:
        raise PlaceError(source, "Pinocchio's terms (M, the spatial inertias) are not finite")
    what, value = max(candidates, key=lambda c: abs(math.log10(abs(c[1]))))
    raise PlaceError(
        source,
        f"{what} {value:g}: the terms Pinocchio builds from it (M, the spatial inertias) overflow "
        "double precision",
    )
