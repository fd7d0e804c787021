"""The items a ``sympy.physics.mechanics`` derivation is written from, and a repair as an edit of one.

A model made from a derivation (``pendverify.analytic.mechanics_model``: ``cls.derivation``)
has M and the forcing f computed by SymPy; the user wrote something else: bodies, particles,
loads, a Lagrangian.  A repair of such a model names what was written (``source_items``):

* a ``KanesMethod`` (its ``bodies`` and ``loads``): each body's or particle's mass, each
  non-zero measure number of a rigid body's central inertia in its own frame (I_ij and I_ji
  together), each load's measure numbers (a force at a point, a torque on a frame), one per
  basis vector of the frame it is written in;
* a ``LagrangesMethod``: when it was given its ``bodies`` and its Lagrangian is theirs,
  L = Σ (T_b − V_b), the bodies' masses and inertias as for Kane and each body's potential
  energy as written; otherwise each term of the Lagrangian.  Its loads (``forcelist``) as for Kane;
* an (M, forcing) pair: nothing (the repair is an edit of an entry, as for any model).

Each item's candidate edits are the single-expression edits of an entry
(``pendverify.diagnosis.candidates.expression_edits``: a sign, a drop, a factor 2 or ½ on one
term, a symbol swapped for another of its kind, sin↔cos, …), applied to the item's expression,
after a sign or factor 2 or ½ on the whole item (``WHOLE_FACTORS``).

**The effect of an edit** Δ = new − old of an item on M q̈ = f.  Lagrange's equations are linear
in L, and the generalised forces linear in the loads, so an edit adds to them what the change
alone gives.  An energy item changes L by δL = w·Δ, w the item's *weight*: ½ v·v for a mass
(v the velocity of the mass centre in the inertial frame), ½ ω_i ω_j for a diagonal inertia
measure number I_ii and ω_i ω_j for I_ij = I_ji (ω in the body's frame), −1 for a body's
potential energy (as written, whole), 1 for a term of L.  With δL(q, q̇):

    δM_ij = ∂²δL/∂q̇_i∂q̇_j,    δf_i = ∂δL/∂q_i − Σ_j ∂²δL/∂q̇_i∂q_j q̇_j

(d/dt ∂δL/∂q̇_i − ∂δL/∂q_i = δM_i· q̈ − δf_i).  A load item, the measure number of basis vector
e of the load at point P (on frame A), changes the generalised force by δf_i = Δ·(e · ∂v_P/∂q̇_i)
(e · ∂ω_A/∂q̇_i).  Kane's equations with the speeds the coordinates' rates (what
``mechanics_model`` accepts) are Lagrange's, and the partial velocities are the same.  The
weights are computed in the method's own symbols and mapped to the model's
(``Derivation.in_model_symbols``); M' = M + δM and f' = f + δf are rebuilt through the pair form
with the same declaration (``Derivation.rebuilt``), and the entries of its closed forms that
differ from the model's are the candidate's entry-level changes, which the repair search
confirms as any other (``pendverify.diagnosis.repair``).
"""

from __future__ import annotations

import dataclasses
import itertools
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.diagnosis.candidates import RANK, expression_edits
from pendverify.diagnosis.clock import now
from pendverify.diagnosis.slots import SCREEN_RTOL
from pendverify.errors import PendverifyError
from pendverify.symbolic.edits import Edit
from pendverify.symbolic.zero_test import is_zero, probe

#: factors of a whole item (of several terms) tried before the edits of one term: the inverses of
#: a sign or factor on the whole of it
WHOLE_FACTORS = (sp.Integer(-1), sp.Integer(2), sp.Rational(1, 2))
#: edits of one item tried at most (the first ones: the simplest are enumerated first)
EDITS_PER_ITEM = 40


@dataclass(frozen=True)
class SourceItem:
    """One thing the user wrote: ``owner`` (``body link2``, ``load on C2``), ``part`` (``inertia``,
    ``mass``, ``N.y``), the expression in the model's symbols, and how it enters (module docstring):
    ``weight`` (δL per unit change) for an energy item, ``load`` (δf_i per unit change) for a load."""

    owner: str
    part: str
    expr: sp.Expr
    weight: sp.Expr | None = None
    load: tuple | None = None

    @property
    def label(self) -> str:
        return f"{self.owner} ({self.part})"

    def name(self, render=str) -> str:
        """The item in the user's words: ``body link2: inertia I2``, ``load on C2: -g*m2*N.y``."""
        if self.load is not None:
            return f"{self.owner}: ({render(self.expr)})*{self.part}"
        return f"{self.owner}: {self.part} {render(self.expr)}"


@dataclass(frozen=True)
class SourceEdit:
    """One edit of one source item (``edit``: of the item's expression)."""

    item: SourceItem
    edit: Edit

    # what the repair search reads of an edit (``Edit``'s fields)
    @property
    def operator(self) -> str:
        return self.edit.operator

    @property
    def old(self):
        return self.item.expr

    @property
    def new(self):
        return self.edit.expr

    @property
    def expr(self):
        return self.edit.expr

    @property
    def what(self) -> str:
        return f"{self.item.label}: {self.item.expr} → {self.edit.expr}"

    def shown(self, render=str) -> str:
        return f"{self.item.label}: {render(self.item.expr)} → {render(self.edit.expr)}"

    @property
    def rank(self) -> int:
        """As the entry edits are ranked (``candidates.RANK``); a factor −1 is a sign, 0 a drop."""
        if self.edit.operator == "scale" and self.edit.new == -self.edit.old:
            return RANK["sign"]
        if self.edit.operator == "scale" and self.edit.new == 0:
            return RANK["drop"]
        return RANK.get(self.edit.operator, 9)


def _by_name(sm) -> dict:
    names = {s.name: s for group in sm.symbols.values() for s in group}
    return names | {p.name: p for p in sm.parameters.values()}


class _Mapper:
    """Expressions of the derivation in the SymbolicModel's symbols (by name)."""

    def __init__(self, derivation, sm):
        self.derivation, self.names = derivation, _by_name(sm)

    def __call__(self, expr):
        mapped = self.derivation.in_model_symbols(sp.sympify(expr))
        return mapped.xreplace({s: self.names[s.name] for s in mapped.free_symbols if s.name in self.names})


def _rates(method, kind: str) -> list:
    """The generalised speeds the partial velocities are taken with: u (Kane), q̇ (Lagrange)."""
    if kind == "KanesMethod":
        return list(method.u)
    t = sp.Symbol("t")
    return [q.diff(q.args[0] if q.args else t) for q in method.q]


def _point(body):
    return getattr(body, "masscenter", None) or body.point


def _body_items(body, frame, mapped) -> list[SourceItem]:
    """A body's mass and inertia items (module docstring)."""
    kind = "body" if hasattr(body, "central_inertia") else "particle"
    owner = f"{kind} {body.name}"
    v = _point(body).vel(frame)
    out = [SourceItem(owner, "mass", mapped(body.mass), weight=mapped(v.dot(v) / 2))]
    if kind == "particle":
        return out
    B = body.frame
    omega = B.ang_vel_in(frame)
    w = [mapped(omega.dot(e)) for e in (B.x, B.y, B.z)]
    inertia = body.central_inertia.to_matrix(B)
    axes = "xyz"
    for i in range(3):
        for j in range(i, 3):
            if inertia[i, j] != 0:
                part = (
                    "inertia"
                    if i == j and sum(1 for k in range(3) if inertia[k, k] != 0) == 1
                    else (f"inertia {axes[i]}{axes[j]}")
                )
                weight = w[i] * w[j] / 2 if i == j else w[i] * w[j]
                out.append(SourceItem(owner, part, mapped(inertia[i, j]), weight=weight))
    return out


def _load_items(load, frame, rates, mapped) -> list[SourceItem]:
    """A load's items: the measure numbers of its vector, each with its generalised-force weights."""
    where, vector = load[0], load[1]
    if hasattr(where, "ang_vel_in"):  # a frame: a torque
        velocity = where.ang_vel_in(frame)
    else:
        velocity = where.vel(frame)
    partials = [velocity.diff(r, frame) for r in rates]
    out = []
    for measures, basis in vector.args:
        for k, e in enumerate((basis.x, basis.y, basis.z)):
            if measures[k] != 0:
                load_weights = tuple(mapped(e.dot(p)) for p in partials)
                out.append(
                    SourceItem(f"load on {where.name}", str(e), mapped(measures[k]), load=load_weights)
                )
    return out


def source_items(derivation, sm) -> list[SourceItem]:
    """The items the derivation is written from (module docstring); [] for an (M, forcing) pair, or
    when SymPy cannot give an item's weights (a frame whose angular velocity is not defined) or an
    item cannot be put in the model's symbols: the repair then searches the entries alone."""
    method, kind = derivation.method, derivation.kind
    if kind not in ("LagrangesMethod", "KanesMethod"):
        return []
    mapped = _Mapper(derivation, sm)
    rates = _rates(method, kind)
    try:
        if kind == "KanesMethod":
            frame, bodies, loads = method._inertial, list(method.bodies or ()), list(method.loads or ())
            items = [i for b in bodies for i in _body_items(b, frame, mapped)]
        else:
            frame, bodies = method.inertial, list(method._bodies or ())
            loads = list(method._forcelist or ())
            L = method._L[0] if isinstance(method._L, sp.MatrixBase) else method._L
            items = _lagrangian_items(L, bodies, frame, mapped)
        for load in loads:
            items += _load_items(load, frame, rates, mapped)
    except (PendverifyError, AttributeError, TypeError, ValueError):
        return []
    for position, expr in derivation.written:  # an item written otherwise (``Derivation.edited``)
        items[position] = dataclasses.replace(items[position], expr=mapped(expr))
    return items


def _lagrangian_items(L, bodies, frame, mapped) -> list[SourceItem]:
    if bodies:
        energies = sp.Add(*[b.kinetic_energy(frame) - b.potential_energy for b in bodies])
        if sp.expand(L - energies) == 0:
            items = [i for b in bodies for i in _body_items(b, frame, mapped)]
            for b in bodies:
                kind = "body" if hasattr(b, "central_inertia") else "particle"
                if b.potential_energy != 0:  # as written: one occurrence of its mass, not expanded
                    energy = mapped(b.potential_energy)
                    items.append(SourceItem(f"{kind} {b.name}", "potential energy", energy, weight=-sp.S.One))
            return items
    return [SourceItem("Lagrangian", "term", mapped(term), weight=sp.S.One) for term in sp.Add.make_args(L)]


def item_edits(item: SourceItem, sm) -> Iterator[SourceEdit]:
    """The candidate edits of one item, simplest first within the item (``EDITS_PER_ITEM`` at most)."""
    seen = set()
    whole = [  # the item as a whole scaled (a load written twice): one factor on all its terms
        Edit("scale", item.expr, k * item.expr, k * item.expr, f"{item.expr} → {k}·({item.expr})")
        for k in WHOLE_FACTORS
        if item.expr.is_Add
    ]
    for edit in itertools.chain(whole, expression_edits(item.expr, sm)):
        if edit.expr == item.expr or edit.expr in seen:
            continue
        seen.add(edit.expr)
        yield SourceEdit(item, edit)
        if len(seen) >= EDITS_PER_ITEM:
            return


def effect(item: SourceItem, new, sm) -> tuple[sp.Matrix, sp.Matrix]:
    """(δM, δf) of the item's expression becoming ``new`` (module docstring)."""
    q, v = sm.symbols["q"], sm.symbols["v"]
    n = len(q)
    delta = new - item.expr
    if item.load is not None:
        return sp.zeros(n, n), sp.Matrix([w * delta for w in item.load])
    dL = item.weight * delta
    grad_v = [sp.diff(dL, vi) for vi in v]
    dM = sp.Matrix(n, n, lambda i, j: sp.expand(sp.diff(grad_v[i], v[j])))
    df = sp.Matrix(
        [sp.diff(dL, q[i]) - sum(sp.diff(grad_v[i], q[j]) * v[j] for j in range(n)) for i in range(n)]
    )
    return dM, df.applyfunc(sp.expand)


def entry_changes(derivation, sm, item: SourceItem, new) -> dict | None:
    """The candidate's changes {(method, index): (old, new)} to the model's closed forms: M' and f'
    rebuilt through the pair form (module docstring); None when the rebuilt model is refused or
    its closed forms are not the model's keys."""
    dM, df = effect(item, new, sm)
    if all(x == 0 for x in dM) and all(x == 0 for x in df):
        return {}
    mapped = _Mapper(derivation, sm)
    M = mapped(derivation.M) + dM
    f = mapped(derivation.forcing) + df
    try:
        rebuilt = SymbolicModel.of(derivation.rebuilt(M, f)).closed_forms
    except PendverifyError:
        return None
    forms = sm.closed_forms
    if set(rebuilt) != set(forms):
        return None
    changes = {}
    for method, value in forms.items():
        olds, news = entries(value), entries(rebuilt[method])
        if len(olds) != len(news):
            return None
        for index, (old, value_new) in enumerate(zip(olds, news, strict=True)):
            d = value_new - old
            if d != 0 and (probe(d) or not is_zero(d, sm.angles)):
                changes[(method, index)] = (old, value_new)
    return changes


class SourceSearch:
    """The source edits of a derivation as the repair search confirms them: simplest first over all
    items (a sign, a drop, a swapped symbol, then factors), each one's entry-level changes screened
    at the screening states before any check runs — it must change every entry that disagrees
    (``slots``) and bring each to what Pinocchio says (``Slot.mismatch`` within ``SCREEN_RTOL``,
    as an entry edit is screened).  ``tried``: the edits whose changes were computed; ``passed``:
    those that passed the screen."""

    def __init__(self, derivation, sm, slots, evaluate, deadline: float):
        self.derivation, self.sm, self.evaluate, self.deadline = derivation, sm, evaluate, deadline
        self.slots = {(s.method, s.index): s for s in slots}
        self.items = source_items(derivation, sm)
        self.tried = self.passed = 0
        self.stopped = False  # at ``deadline``, before every edit was tried

    def _screened(self, changes: dict):
        """The first slot the changes repair when they pass the screen, else None."""
        if not changes or not set(self.slots) <= set(changes):
            return None
        for key, slot in self.slots.items():
            with np.errstate(all="ignore"):
                values = self.evaluate(changes[key][1], slot.symbols)
            if not np.all(np.isfinite(values)) or slot.mismatch(values) > SCREEN_RTOL:
                return None
        return next(iter(self.slots.values()))

    def candidates(self) -> Iterator[tuple[int, dict, SourceEdit, object]]:
        """(rank, changes, the source edit, a slot it repairs), as ``_Confirmation.run`` takes them."""
        edits = sorted((e for item in self.items for e in item_edits(item, self.sm)), key=lambda e: e.rank)
        for edit in edits:
            if now() > self.deadline:
                self.stopped = True
                return
            self.tried += 1
            changes = entry_changes(self.derivation, self.sm, edit.item, edit.new)
            slot = self._screened(changes) if changes else None
            if slot is not None:
                self.passed += 1
                yield edit.rank, changes, edit, slot


def planted_model(model, sm, position: int, new):
    """The model class of ``model``'s derivation with item ``position`` written as ``new``
    (``Derivation.edited``; the corpus of planted errors), or None when it is refused."""
    derivation = type(model).derivation
    item = source_items(derivation, sm)[position]
    dM, df = effect(item, new, sm)
    mapped = _Mapper(derivation, sm)
    try:
        return derivation.edited(position, new, mapped(derivation.M) + dM, mapped(derivation.forcing) + df)
    except PendverifyError:
        return None
