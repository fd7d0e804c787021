"""Parameter sets moved away from the file's values, each with its robot description rewritten.

Why.  Textbook and published parameter sets satisfy relations: a uniform rod's I = m·l²/12
about its centre (m·l²/3 about its end), lc = l/2, m1 = m2, l1 = l2, l = 0.5.  At such values
different formulas give the same numbers, so an edit of a wrong model can make every check pass
on every state and still be the wrong formula (``l*m → l*m/2`` for a missing ``l``, with
l = 0.5; ``I → 4*I`` for a missing m·l², with I = m·l²/12 and lc = l/2).  A repair
(``pendverify.diagnosis.repair``) is therefore checked again at other parameter values, the
robot description rewritten for each, as a sweep does for a user's model
(``pendverify.robot.rebind.Binding``, ``pendverify.certify.sweep_task.set_urdf``), or, for a
description that is not rewritten, its Pinocchio model moved (below).

Derivation.  Let c be the edited entry and t the entry that makes the checks pass; both are
functions of the state q and the parameters p.  An edit that passes at the file's values p0
on every state has c(q, p0) = t(q, p0) for every q, so d = c − t, a function of p alone on
the states, vanishes at p0.  Unless d ≡ 0 (c is t), its zeros form a hypersurface of parameter
space, and a set whose parameters are each moved by an independent random factor lands on it
with probability zero; it lands within the checks' tolerance of it (some ε of the terms'
size, ~1e-13) with a probability of the order of that tolerance over the move's size, ~1e-12.
One set would do; ``SETS`` = 2 makes an accidental near-zero of one draw irrelevant (it would
have to recur in an independent draw), at the cost of one more check run for each edit that
already passed at the file's values, of which there are few.

The factors.  Each factor is exp(±u), u uniform in [``LEAST_MOVE``, ``MOST_MOVE``] = [0.1,
0.3], the sign drawn too: every parameter moves by 10 % to 35 %.  At least 10 %, so that a
relation broken by the move is broken by ~10 % of the terms' size, some 1e11 times the checks'
tolerance; at most 35 %, so that the robot stays of the same size and shape (masses and
lengths stay positive whatever the factor; the conditioning and tolerances stay the user's
robot's).  Factors are continuous draws, so that moved parameters do not fall onto new simple
relations (a ratio of 2) either.

Moments of inertia.  Where a link's three moments are three parameters (Ixx, Iyy, Izz, bound
alone), moving each by its own factor can leave the triangle inequality Izz ≤ Ixx + Iyy, which a
thin or flat body meets almost with equality (Furuta's arm: 1.057e-3 ≤ 1.060e-3), and the strict
reader refuses that URDF (``ModelBinding`` that model).  The factors then move the body's second
moments of mass instead, A = ∫x² dm = (Iyy + Izz − Ixx)/2, B = (Ixx + Izz − Iyy)/2,
C = (Ixx + Iyy − Izz)/2 (all ≥ 0 by the triangle inequality), and the moments follow:
Ixx = B + C, Iyy = A + C, Izz = A + B.  They then satisfy the inequality whatever the
factors, and still move apart (by the moved share of B and C: 0.5 % of Iyy for Furuta's arm,
some 1e10 times the checks' tolerance).  A body that is exactly flat (C = 0) keeps
Izz = Ixx + Iyy: a physical identity, not a coincidence.  Any other rule a draw breaks (a rule
across parameters, the strict reader) makes it drawn again, up to ``DRAWS`` times per set.

Where the parameters move.  What the checks compare a model with is the Pinocchio model read
from the description: a kinematic tree whose dynamics are a function of its joints' placements
and of each joint's body inertia (mass, centre of mass, rotational inertia about it; the
equations of motion are linear in the inertial parameters).  A URDF or xacro is rewritten
(``rebind.Binding``: a parameter's value found in ``<inertial>``, a joint's ``<origin>`` or
``<dynamics>``) and read again.  An MJCF, an SDFormat file or a ``pinocchio.Model`` given to the
API is not rewritten; its Pinocchio model is moved instead (``robot.model_rebind.ModelBinding``:
the value found in ``inertias[j]``'s mass, lever or rotational inertia, in
``jointPlacements[j].translation``, in a declared joint damping or armature), with the same matching
rules, and each set's system is built from the moved copy.  Both are the same function of the
parameters: the reader copies each number of the file into one field of the model unchanged
(where it combines numbers, no parameter is found there), so moving the value in the model is
what rewriting it in the file and reading it again would give.  Nothing else a check reads comes
from the file: the closed form's parameters are read off the moved model by the model's geometry
reader, the declared damping is moved in the description's facts with ``model.damping``, an
MJCF's armature in ``model.armature`` (where a parameter holds its value; else it stays as
read), its gravity is g's (above); MuJoCo's and Drake's cross-checks compare a file with its
reading and are not run again (there is no moved file).

Which parameters move (``Perturbation``):

* gravity (``IN_PINOCCHIO``): freely; each set's system is built with its g;
* damping, where the description declares no damping: freely (the checks compare D with nothing
  in it, ``needs_urdf_damping``);
* every other parameter the binding finds alone (in the URDF, or in the Pinocchio model of an
  MJCF, SDFormat or Pinocchio-model description): on its own (*independent*);
* parameters that share a value (``groups``: m1 = m2): together, by one factor, so they stay
  equal.  Two edits that differ only by exchanging members of a group agree at every such set:
  a repair that involves a member is not told apart from its exchange;
* the rest are not moved, each with the reason (a value 0, a value the description holds
  nowhere alone: a drawing length, a combination of parameters such as an inertia about the
  joint or a centre of mass in a turned frame), and so the repairs that involve them hold at
  these values only;
* nor is a parameter the description holds alone at one site and combined with others
  elsewhere (a tip frame at l, the centre of mass at l/2 and m·l²/12): moved, it makes entries
  of the model that agree with the description at the file's values disagree, and then a right
  repair would fail too.  ``consistent`` (given by the repair search: no entry that agrees at the
  file's values disagrees at the set) finds it, each move tried alone when a set is not
  consistent.

A moved rotational inertia must stay a rigid body's: in a URDF the strict reader refuses one
that is not; in a Pinocchio model ``ModelBinding.rewrite`` does (the same rules).  Either way the
draw is made again, and the moments of a triple of parameters move through the second moments
of mass (above), so they keep the triangle inequality.

The sets are drawn with ``SEED``: the same model gets the same sets every time.
"""

from __future__ import annotations

import dataclasses
import math
import random
from dataclasses import dataclass, field

from pendverify.errors import PendverifyError
from pendverify.robot.description import READERS
from pendverify.robot.model_rebind import ModelBinding
from pendverify.robot.pinocchio_model import FORMAT as PINOCCHIO
from pendverify.robot.rebind import IN_PINOCCHIO, Binding, Bound

SETS = 2
LEAST_MOVE, MOST_MOVE = 0.1, 0.3  # |ln factor| (module docstring)
DRAWS = 4  # draws per set before giving up on it (a refused URDF, a rule across parameters)
SEED = 35
#: description formats ``Binding`` rewrites (xacro: the URDF it expanded to)
REWRITTEN = ("urdf", "xacro")


@dataclass(frozen=True)
class MovedSet:
    """One perturbed parameter set: the values, the model at them and its description's system."""

    params: object
    model: object
    system: object


@dataclass
class Perturbation:
    """The perturbed sets of one model and description, and how each parameter was treated."""

    sets: list[MovedSet] = field(default_factory=list)
    #: parameters moved each by its own factor (gravity, free damping, bound alone)
    independent: tuple[str, ...] = ()
    #: parameters that share a value, moved together by one factor
    groups: tuple[tuple[str, ...], ...] = ()
    #: parameter → why it was not moved
    fixed: dict[str, str] = field(default_factory=dict)
    #: what the sets changed in the description, for the message: "the URDF rewritten for each"
    how: str = ""
    #: why there are fewer sets than ``SETS`` (every draw refused), or ""
    refused: str = ""

    def why_not_alone(self, names) -> list[str]:
        """Why each of ``names`` was not moved on its own, in words (empty: all were)."""
        out, equal = [], []
        for group in self.groups:
            inside = [n for n in group if n in set(names)]
            if inside:  # the edit's own first: "m2 = m1"
                equal.append(" = ".join(inside + [n for n in group if n not in inside]))
        if equal:
            out.append(f"{', '.join(equal)} here and at every set (equal values are moved together)")
        out += [f"{n} was not moved ({self.fixed[n]})" for n in sorted(set(names) & set(self.fixed))]
        if not self.sets and not out:
            out.append(f"no parameter set could be made ({self.refused or 'nothing to move'})")
        return out

    def unmoved_beside(self, involved, used) -> list[str]:
        """Why an edit of ``involved`` that held at every set is not confirmed for the parameters of
        ``used`` (those the model uses) that were not moved, in words (empty: every one moved).  A
        parameter left at its value is the same number at every set, and an edit's number can
        stand for it: with lc = 0.25 unmoved, ``g*m*sin(theta)/4`` holds at every set where
        ``g*lc*m*sin(theta)`` is right."""
        hidden = sorted(set(self.fixed) & set(used) - set(involved))
        if not hidden or not self.sets:
            return []
        reasons = "; ".join(f"{n}: {self.fixed[n]}" for n in hidden[:3]) + ("; …" if len(hidden) > 3 else "")
        if len(hidden) > 3:
            names = f"{', '.join(hidden[:3])} and {len(hidden) - 3} more"
        else:
            names = " and ".join(filter(None, (", ".join(hidden[:-1]), hidden[-1])))
        one = len(hidden) == 1
        return [
            f"{names} of your model {'was' if one else 'were'} not moved ({reasons}), so an edit whose "
            f"numbers stand for {'its value' if one else 'their values'} holds at every set as well"
        ]


def perturbations(model, system, consistent=None, count: int = SETS, seed: int = SEED) -> Perturbation:
    """The perturbed sets of ``model``'s parameters on ``system``'s description (module docstring).

    ``consistent(model, system)``, when given, says whether a set's description still agrees with
    the model where it agreed at the file's values; a set that does not is not kept, and each
    parameter (or group) whose move alone breaks that agreement is not moved (module docstring)."""
    params = model.params
    if not dataclasses.is_dataclass(params):
        return Perturbation(refused="the parameters are not a parameter set")
    kinds = {f.name: f.metadata.get("kind") for f in dataclasses.fields(params)}
    loaded = system.urdf
    binding, cause = None, ""
    if loaded is None:
        cause = "the system has no description to rebuild"
    elif loaded.format in REWRITTEN:
        try:
            binding = Binding.of(loaded.text, params, loaded.source)
        except PendverifyError as exc:
            cause = f"the description could not be read for rewriting: {exc}"
    else:  # MJCF, SDFormat, a Pinocchio model: moved in the model read (module docstring)
        binding = ModelBinding.of(loaded, params)
    free_damping = system.urdf_damping() is None
    units, fixed, written = [], {}, set()
    for name, kind in kinds.items():
        value = float(getattr(params, name))
        if kind in IN_PINOCCHIO or (kind == "damping" and free_damping):
            if value == 0:
                fixed[name] = "its value is 0"
            elif kind in IN_PINOCCHIO and (name != "g" or system.tilt is not None or loaded is None):
                # the system takes the closed form's g from the set's ``g`` (``model_target``) along −z
                fixed[name] = "the robot's gravity is not taken from it"
            else:
                units.append((name,))
        elif binding is None:
            fixed[name] = cause
        elif binding.bound(name):
            units.append((name,))
            written.add(name)
        elif binding.group_of(name) is None:
            fixed[name] = binding.reasons[name]
    if binding is not None:
        units += list(binding.groups)
        written |= {n for group in binding.groups for n in group}
    out = Perturbation(fixed=fixed)
    rewritten = bool(written)
    if not rewritten:
        out.how = "another g for each"
    elif isinstance(binding, ModelBinding):  # a Pinocchio model given as one is its own description
        whose = "the" if loaded.format == PINOCCHIO else f"the {READERS[loaded.format]}'s"
        out.how = f"{whose} Pinocchio model moved for each"
    else:
        out.how = f"the {READERS[loaded.format]} rewritten for each"

    triples = _moment_triples(binding) if binding is not None else []

    def made(factors: dict) -> MovedSet:
        values = dict(params.as_dict())
        for unit, factor in factors.items():
            for name in unit:
                values[name] *= factor
        for x, y, z in triples:  # the second moments moved, not the principal moments (docstring)
            ix, iy, iz = (float(getattr(params, n)) for n in (x, y, z))
            a, b, c = (iy + iz - ix) / 2, (ix + iz - iy) / 2, (ix + iy - iz) / 2
            fa, fb, fc = (factors.get((n,), 1.0) for n in (x, y, z))
            values[x], values[y], values[z] = fb * b + fc * c, fa * a + fc * c, fa * a + fb * b
        moved = type(params).from_mapping(values, "<perturbed parameters>")
        # what moves freely is not in the description: it keeps the file's values there
        kept = moved.replace(**{n: getattr(params, n) for n in kinds if n not in written})
        description = binding.rewrite(kept) if rewritten else loaded
        moved_system = type(system).for_model(
            type(model), description, getattr(moved, "g", None), system.source
        )
        moved_system.model_form_rtol = system.model_form_rtol
        return MovedSet(moved, type(model)(moved), moved_system)

    rng = random.Random(seed)
    for _ in range(count * DRAWS):
        if len(out.sets) == count or not units:
            break
        factors = {unit: _factor(rng) for unit in units}
        try:
            moved = made(factors)
        except (PendverifyError, ValueError, ArithmeticError) as exc:  # a rule, the strict reader
            out.refused = str(exc)
            continue
        if consistent is None or consistent(moved.model, moved.system):
            out.sets.append(moved)
            continue
        culprits = []
        for unit in list(units):  # which move breaks what agreed: each alone
            try:
                alone = made({unit: factors[unit]})
            except (PendverifyError, ValueError, ArithmeticError):
                continue
            if not consistent(alone.model, alone.system):
                culprits.append(unit)
        if not culprits:  # only moves together break it: no set is made
            out.refused = "moved together, the parameters make entries that agree here disagree"
            units.clear()
        holder = "the Pinocchio model" if isinstance(binding, ModelBinding) else "the URDF"
        for unit in culprits:
            units.remove(unit)
            for name in unit:
                out.fixed[name] = (
                    f"moved in {holder}, entries that agree at the file's values disagree: "
                    f"{holder} holds it combined with other parameters too"
                )
        out.sets.clear()  # the sets kept so far moved those as well
    grouped = set(binding.groups) if binding is not None else set()
    out.independent = tuple(u[0] for u in units if u not in grouped)
    out.groups = tuple(u for u in units if u in grouped)
    if not units:
        out.refused = out.refused or "no parameter can be moved"
    return out


def _moment_triples(binding: Bound) -> list[tuple[str, str, str]]:
    """(ixx, iyy, izz parameters) of each inertia (a URDF's ``<inertia>``, a Pinocchio body's
    rotational inertia) whose three moments are three parameters, each bound there alone."""
    by_element: dict = {}
    for name, sites in binding.sites.items():
        if len(sites) == 1 and sites[0][1].attribute in ("ixx", "iyy", "izz"):
            site = sites[0][1]
            by_element.setdefault(site.path, {})[site.attribute] = name
    return [(d["ixx"], d["iyy"], d["izz"]) for d in by_element.values() if len(d) == 3]


def _factor(rng: random.Random) -> float:
    """exp(±u), u uniform in [LEAST_MOVE, MOST_MOVE] (module docstring)."""
    return math.exp(rng.choice((-1, 1)) * rng.uniform(LEAST_MOVE, MOST_MOVE))
