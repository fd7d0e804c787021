"""A changed parameter set moved into a loaded Pinocchio model, for a description not rewritten.

An MJCF, an SDFormat file or a ``pinocchio.Model`` given to the API is not rewritten
(``pendverify.robot.rebind`` rewrites a URDF's text).  What every check evaluates is the
Pinocchio model read from it: a kinematic tree whose dynamics are those of its joints'
placements and of each joint's body inertia, the rigid-body equations being linear in each
body's inertial parameters (mass m, first moment m·c, rotational inertia) and a function of the
placements.  ``ModelBinding.of`` finds, for each parameter, the fields of the model that hold its
value, by kind, with ``rebind.match``: the rules ``Binding`` applies to a URDF's attributes.

=========  ==============================================================================
kind       where its value is looked for (j: each joint but the universe)
=========  ==============================================================================
mass       ``model.inertias[j].mass``; a slide's armature ``model.armature`` (kg)
inertia    ``model.inertias[j].inertia`` (about the centre of mass): ixx … izz (|value|);
           a hinge's armature ``model.armature`` (kg·m², a rotor inertia on M's diagonal)
length     the components of ``model.inertias[j].lever`` (the centre of mass in the joint's
offset     frame) and of ``model.jointPlacements[j].translation`` (|value|; the sign is kept)
damping    a joint's damping the description declares (its facts, and ``model.damping``)
gravity    nowhere: the system takes g from the parameter set
=========  ==============================================================================

An armature is looked for on joints of one degree of freedom whose armature is not 0 (an MJCF's
``armature``, which the reader copies from MuJoCo's ``dof_armature``), under both kinds: the
value's unit depends on the joint, which the kind does not say.

``rewrite`` gives a copy of the description read (``LoadedDescription``) whose model holds the
new values at those fields: what rewriting the file at the same places would give, since the
reader copies each of those numbers into the model (a joint's placement, a body's inertia)
unchanged when the body is alone on its joint.  Where a reader combined numbers (bodies welded
onto one joint, a centre of mass carried through a rotated frame), the model holds the
combination, no parameter's value is found there, and the parameter is unbound with its reason,
as in a URDF.  The copy's text is empty and its origins are dropped: the file's text no longer
describes the moved model, and nothing of the file is read again (a MuJoCo or Drake cross-check
compares a file with its reading: there is no moved file to compare).

The moved model must stay a rigid body's: every rotational inertia changed is positive
semi-definite and its principal moments λ1 ≥ λ2 ≥ λ3 satisfy λ1 ≤ λ2 + λ3, to within
δ = ``FLOAT_SLACK``·ε·‖I‖_F (the eigensolver's backward error; ``robot.inertia_rounding``),
or ``rewrite`` refuses it naming the joint.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from pendverify.analytic import ParameterSet
from pendverify.errors import RebindError
from pendverify.robot.description import LoadedDescription
from pendverify.robot.inertia_rounding import FLOAT_SLACK
from pendverify.robot.rebind import Bound, Site, changes, match
from pendverify.robot.strict import JointDynamics

_ENTRIES = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
#: kind -> where its value is looked for, in words
WHERE = {
    "mass": "masses (inertias[j].mass) or joint armatures (armature)",
    "inertia": "rotational inertias about the centres of mass (inertias[j].inertia) or joint armatures "
    "(armature)",
    "length": "centres of mass (inertias[j].lever) or joint placements (jointPlacements[j].translation)",
    "offset": "centres of mass (inertias[j].lever) or joint placements (jointPlacements[j].translation)",
    "damping": "declared joint damping",
}
_EPS = float(np.finfo(float).eps)


@dataclass
class ModelBinding(Bound):
    """Where each parameter of a set sits in a loaded Pinocchio model (module docstring)."""

    loaded: LoadedDescription
    params: ParameterSet
    sites: dict[str, list[tuple[int, Site]]] = field(default_factory=dict)
    reasons: dict[str, str] = field(default_factory=dict)
    groups: dict[tuple[str, ...], list[tuple[int, Site]]] = field(default_factory=dict)

    @classmethod
    def of(cls, loaded: LoadedDescription, params: ParameterSet) -> ModelBinding:
        binding = cls(loaded, params)
        match(binding, lambda kind: _found(loaded, kind), "the Pinocchio model", WHERE.get)
        return binding

    def rewrite(self, params: ParameterSet) -> LoadedDescription:
        """The description read, its model holding ``params`` where it held the parameters'
        values (module docstring); an inertia that is no rigid body's is refused by joint."""
        loaded = self.loaded
        model = loaded.model.copy()
        dynamics = dict(loaded.facts.joint_dynamics)
        changed = set()
        for j, site, value in changes(self, params, "the Pinocchio model"):
            if site.path.startswith("jointPlacements"):
                placement = model.jointPlacements[j]
                translation = placement.translation.copy()
                translation[site.component] = value
                model.jointPlacements[j] = pin.SE3(placement.rotation, translation)
            elif site.path.startswith("joint_dynamics"):
                name = model.names[j]
                dynamics[name] = JointDynamics(value, dynamics[name].friction)
                damping = np.array(model.damping, dtype=float)
                damping[model.joints[j].idx_v] = value
                model.damping = damping
            elif site.path.startswith("armature"):
                armature = np.array(model.armature, dtype=float)
                armature[model.joints[j].idx_v] = value
                model.armature = armature
            else:
                inertia = model.inertias[j]
                mass, lever, rotational = inertia.mass, inertia.lever.copy(), inertia.inertia.copy()
                if site.attribute == "mass":
                    mass = value
                elif site.attribute == "lever":
                    lever[site.component] = value
                else:
                    r, c = _ENTRIES[site.attribute]
                    rotational[r, c] = rotational[c, r] = value
                    changed.add(j)
                model.inertias[j] = pin.Inertia(mass, lever, rotational)
        for j in sorted(changed):
            _check_rigid(model.inertias[j].inertia, f"{loaded.source}: joint {model.names[j]!r}")
        facts = dataclasses.replace(loaded.facts, joint_dynamics=dynamics)
        return dataclasses.replace(loaded, model=model, facts=facts, text="", origins={})


def _found(loaded: LoadedDescription, kind: str):
    """(joint, ``Site``, value) of every field of ``loaded``'s model a ``kind`` may sit at."""
    model = loaded.model
    if kind not in WHERE:
        return f"its kind {kind!r} is not one the Pinocchio model holds"
    out = []

    def put(j: int, path: str, attribute: str, component, value: float) -> None:
        out.append((j, Site(f"{path}[{j}]", attribute, component, -1.0 if value < 0 else 1.0), float(value)))

    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        one = model.joints[j].nv == 1
        if kind in ("mass", "inertia") and one and model.armature[model.joints[j].idx_v] != 0:
            put(j, "armature", "armature", None, model.armature[model.joints[j].idx_v])
        if kind == "mass":
            put(j, "inertias", "mass", None, inertia.mass)
        elif kind == "inertia":
            for attribute, (r, c) in _ENTRIES.items():
                put(j, "inertias", attribute, None, inertia.inertia[r, c])
        elif kind in ("length", "offset"):
            for c in range(3):
                put(j, "inertias", "lever", c, inertia.lever[c])
                put(j, "jointPlacements", "translation", c, model.jointPlacements[j].translation[c])
        else:  # damping: where the description declares it, on a joint of one degree of freedom
            declared = loaded.facts.joint_dynamics.get(model.names[j])
            if declared is not None and declared.damping is not None and one:
                put(j, "joint_dynamics", "damping", None, declared.damping)
    return out


def _check_rigid(rotational: np.ndarray, place: str) -> None:
    """Refuse a rotational inertia that is no rigid body's (module docstring)."""
    delta = FLOAT_SLACK * _EPS * float(np.linalg.norm(rotational))
    low, mid, high = np.linalg.eigvalsh(rotational)
    if low < -delta or high > mid + low + 3 * delta:
        raise RebindError(
            f"{place}: the moved rotational inertia has principal moments {[low, mid, high]}, "
            "which no rigid body has (each ≥ 0, the largest ≤ the sum of the others)"
        )
