"""The repair: a single edit of the model's own expressions after which every check passes.

1. **Where.** The model's written closed forms are read as SymPy expressions
   (``pendverify.analytic.symbolic_reading``) and each entry is evaluated at the screening
   states (the first ``SCREEN_STATES`` judged states, special ones first) next to what it
   must equal there according to Pinocchio (``targets``): M, H, det M, M⁻¹, q̈, C·q̇
   directly; V up to a constant (both centred); D the URDF's where it declares damping; a
   Coriolis-type matrix (C, or C + D) through its rows' product with q̇, since C itself is
   not unique; a form beyond the interface through what it ``equals``.  An entry whose
   values differ by more than ``SCREEN_RTOL`` of its size is a *slot* to repair.
2. **What.** Per slot, the edits of ``pendverify.symbolic.edits`` (the inverses of
   ``pendverify mutate``'s operators) are evaluated at the screening states, vectorised
   over them, and those that make the slot agree are kept.  Two kinds are solved for rather
   than enumerated: a coefficient k on one term (t → k·t), fitted by least squares over the
   states and kept when k is a simple fraction (denominator ≤ ``DENOMINATOR``) or the
   inverse of a 1e-3 scale — this undoes a sign (k = −1), a dropped or duplicated term
   (k = 0, ½), a factor 2 or ½; and an added term, the entry's difference fitted by the
   basis of ``pendverify.diagnosis.patterns`` with each coefficient matched to a fraction
   times a product of at most ``DEGREE`` parameters — this undoes a dropped term and an
   inertia about the pivot (± m·r²).  An edit is applied where the same expression stands
   in other slots too (a shared sub-expression in code, a shorthand in a LaTeX file); with two
   slots and no single edit, pairs of their edits are tried.
3. **Confirmed.** A candidate becomes a repair only when the edited model
   (``pendverify.symbolic.edited``) passes every applicable check on every state of the
   report's batch; candidates are confirmed simplest first, at most ``CONFIRMATIONS`` of
   them, within the time bound.  Once one is confirmed, other edits of the same entries are
   confirmed too (up to ``ALTERNATIVES``) and shown as alternatives: with the given parameter
   values two edits can give the same numbers (m = 2·m2 makes m2 → m the same as a factor 2),
   and the checks cannot tell which one the derivation meant.

Screening tolerance: a right entry and Pinocchio's value differ by rounding, a few ε of the
terms' size times the cancellation; ``SCREEN_RTOL`` = 1e-7 of the entry's size leaves a
margin of 1e8 ε for that and is still far below any edit (a 1e-3 scale changes a term by
1e-3 of itself).  It only selects candidates: the checks decide.
"""

from __future__ import annotations

import dataclasses
import itertools
import time
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.notation import Notation
from pendverify.diagnosis.patterns import basis_for, fit
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import Edit, replace_at, structural_edits, sums, walk, with_term

SCREEN_STATES = 24
SCREEN_RTOL = 1e-7
DENOMINATOR = 12
DEGREE = 3
CONFIRMATIONS = 12
#: confirmed edits of the same entries shown besides the first: parameter values can make two
#: edits give the same numbers (a parameter worth twice another, a 3·I = m·r²)
ALTERNATIVES = 2
MAX_PAIRS = 40
QUANTITY = {
    "mass_matrix": "M",
    "coriolis_matrix": "C",
    "coriolis_force": "Cqdot",
    "gravity": "H",
    "potential_energy": "V",
    "damping_matrix": "D",
    "det_mass_matrix": "detM",
    "inverse_mass_matrix": "Minv",
    "acceleration": "qddot",
}


@dataclass
class Slot:
    """One entry of a written closed form that disagrees with what Pinocchio says it must be."""

    method: str
    index: int  # row-major into the method's value
    label: str
    expr: sp.Expr
    symbols: list
    values: np.ndarray  # the entry at the screening states
    target: np.ndarray | None  # what it must be (None: a Coriolis row, see ``row``)
    #: a Coriolis-type row: (the row's residual (X − X_pin)·q̇ at the states, q̇_j)
    row: tuple | None = None
    centred: bool = False  # V: compared up to a constant
    scale: float = 1.0
    matches: list = field(default_factory=list)

    def mismatch(self, candidate: np.ndarray) -> float:
        if self.row is not None:
            residual, rate = self.row
            return float(np.max(np.abs(residual + (candidate - self.values) * rate))) / self.scale
        diff = candidate - self.target
        if self.centred:
            diff = diff - np.mean(diff)
        return float(np.max(np.abs(diff))) / self.scale


@dataclass(frozen=True)
class Candidate:
    """Edits of one or more slots: {(method, index): (original entry, new entry)}; the edit shown."""

    changes: tuple
    edit: Edit
    slot: Slot
    rank: int


def _evaluator(sm: SymbolicModel, arrays: dict, params: list):
    """f(expr, args) → the expression's values at the screening states (vectorised)."""
    n = len(arrays["q"])

    def evaluate(expr, args: str) -> np.ndarray:
        symbols = sm.flat_arguments(args) + list(sm.parameters.values())
        columns = [arrays[a][:, k] for a in args for k in range(arrays[a].shape[1])]
        with np.errstate(all="ignore"):
            value = sp.lambdify(symbols, expr, modules="numpy", docstring_limit=0)(*columns, *params)
        return np.broadcast_to(np.asarray(value, dtype=float), (n,))

    return evaluate


class _Matrix:
    """A 2-D array whose ``*`` is the matrix product, as ``equals`` strings write it (SymPy's)."""

    def __init__(self, a):
        self.a = np.asarray(a, dtype=float)

    @staticmethod
    def _of(x):
        return x.a if isinstance(x, _Matrix) else x

    def __mul__(self, other):
        o = self._of(other)
        return _Matrix(self.a @ o if np.ndim(o) == 2 else self.a * o)

    def __rmul__(self, other):
        return _Matrix(other * self.a)

    def __add__(self, other):
        return _Matrix(self.a + self._of(other))

    __radd__ = __add__

    def __sub__(self, other):
        return _Matrix(self.a - self._of(other))

    def __rsub__(self, other):
        return _Matrix(self._of(other) - self.a)

    def __neg__(self):
        return _Matrix(-self.a)


def _equals_targets(form, terms, k: int, D, B, W):
    """What a form beyond the interface equals at state k, from Pinocchio's M, C, H."""

    def column(x):
        return _Matrix(np.reshape(x, (-1, 1)))

    namespace = {
        "M": _Matrix(terms.M_pin[k]),
        "C": _Matrix(terms.C_pin[k]),
        "H": column(terms.H_pin[k]),
        "D": _Matrix(D),
        "B": _Matrix(np.reshape(B, (len(terms.q[k]), -1))),
        "W": _Matrix(np.reshape(W, (len(terms.q[k]), -1))),
        "q": column(terms.q[k]),
        "v": column(terms.v[k]),
        "u": column(terms.u[k]),
        "w": column(terms.w_in[k]),
    }
    value = eval(form.equals, {"__builtins__": {}}, namespace)  # the model class's own declaration
    return np.asarray(value.a if isinstance(value, _Matrix) else value, dtype=float)


def _targets(batch, method: str, form, shape) -> tuple[np.ndarray | None, bool, bool]:
    """(what the method must be at each screening state, whether it is a Coriolis row form,
    whether it is compared up to a constant), or (None, …) when Pinocchio does not say."""
    t = batch.terms
    n = len(batch)
    system = batch.system
    D = t.D_urdf if np.any(system.urdf_damping()) else t.D
    fixed = {
        "mass_matrix": lambda: t.M_pin,
        "gravity": lambda: t.H_pin,
        "potential_energy": lambda: t.V_pin,
        "det_mass_matrix": lambda: t.det_pin,
        "inverse_mass_matrix": lambda: t.Minv_pin,
        "acceleration": lambda: t.a_pin,
        "coriolis_force": lambda: t.bias_pin - t.H_pin,
        "coriolis_matrix": lambda: t.bias_pin - t.H_pin,
        "damping_matrix": lambda: np.broadcast_to(t.D_urdf, (n, *np.shape(t.D_urdf))),
    }
    if method == "damping_matrix" and not np.any(system.urdf_damping()):
        return None, False, False
    if method in fixed:
        return (
            np.asarray(fixed[method](), dtype=float),
            method == "coriolis_matrix",
            method == "potential_energy",
        )
    if not form.equals:
        return None, False, False
    values = np.array([_equals_targets(form, t, k, D, t.B, t.W) for k in range(n)])
    row = form.args == "qv" and "C" in form.equals and len(shape) == 2 and shape[0] == shape[1]
    if row:  # the rows' product with q̇
        values = (values @ t.v[:, :, None])[..., 0]
    return values.reshape((n, -1) if not row else (n, shape[0])), row, False


def _label(method: str, value, index: int) -> str:
    name = QUANTITY.get(method, method)
    if not isinstance(value, sp.MatrixBase):
        return name
    r, c = divmod(index, value.shape[1])
    return f"{name}[{r + 1}]" if value.shape[1] == 1 else f"{name}[{r + 1},{c + 1}]"


def find_slots(batch, sm: SymbolicModel) -> list[Slot]:
    """Every entry of a written closed form that disagrees with Pinocchio at the screening states."""
    model = batch.model
    params = [float(getattr(model.params, p)) for p in sm.parameters]
    arrays = {"q": batch.Q, "v": batch.V, "u": batch.U, "w": batch.W}
    evaluate = _evaluator(sm, arrays, params)
    forms = type(model).closed_forms
    slots = []
    for method, value in sm.closed_forms.items():
        form = forms[method]
        shape = value.shape if isinstance(value, sp.MatrixBase) else ()
        with np.errstate(all="ignore"):
            target, row, centred = _targets(batch, method, form, shape)
        if target is None:
            continue
        flat = entries(value)
        current = np.stack([evaluate(e, form.args) for e in flat], axis=-1) if flat else None
        if row:
            cols = shape[1]
            X = current.reshape(len(batch), shape[0], cols)
            residual = (X @ batch.V[:, :, None])[..., 0] - target
        target = target.reshape(len(batch), -1)
        # an entry is judged against the size of its whole quantity: an exact zero where
        # Pinocchio rounds to 1e-17 is not a difference
        size = float(np.max(np.abs(target), initial=0.0)) + float(np.max(np.abs(current), initial=0.0))
        for index, expr in enumerate(flat):
            values = current[:, index]
            if row:
                r, c = divmod(index, shape[1])
                rate = batch.V[:, c]
                scale = float(np.max(np.abs(target))) + float(np.max(np.abs(X * batch.V[:, None, :])))
                slot = Slot(method, index, _label(method, value, index), expr, form.args, values, None,
                            (residual[:, r], rate), scale=scale or 1.0)  # fmt: skip
                if np.max(np.abs(residual[:, r])) > SCREEN_RTOL * slot.scale and np.any(rate != 0):
                    slots.append(slot)
                continue
            goal = target[:, index]
            diff = values - goal
            if centred:
                diff = diff - np.mean(diff)
            scale = size or 1.0
            if np.max(np.abs(diff)) > SCREEN_RTOL * scale or not np.all(np.isfinite(values)):
                slots.append(Slot(method, index, _label(method, value, index), expr, form.args, values, goal,
                                  None, centred, scale))  # fmt: skip
    return slots


#: the coefficients a one-term edit may put right: a sign, a dropped term, a factor 2 or ½
#: (a duplicated term), and the inverse of ``pendverify mutate``'s 1e-3 scale
COEFFICIENTS = (Fraction(-1), Fraction(0), Fraction(2), Fraction(1, 2), Fraction(1000, 1001))


def _nice(k: float) -> Fraction | None:
    """k as one of ``COEFFICIENTS`` when it is one to rounding."""
    if not np.isfinite(k):
        return None
    return next((c for c in COEFFICIENTS if abs(float(c) - k) <= 1e-9 * max(1.0, abs(k))), None)


def _affine(expr, path) -> bool:
    """Whether the entry is affine in the coefficient of the term at ``path`` (only sums and
    products above it)."""
    node = expr
    for i in path:
        if not (node.is_Add or node.is_Mul):
            return False
        node = node.args[i]
    return True


def _coefficient_edits(slot: Slot, evaluate) -> list[Edit]:
    """t → k·t for one term: k solved for by least squares where the entry is affine in it,
    each of ``COEFFICIENTS`` tried where it is not (inside a power or a function)."""
    out = []
    if slot.row is None:
        goal = slot.target
    else:  # the entry value that zeroes the row's residual, where its rate is not zero
        with np.errstate(all="ignore"):
            goal = slot.values - slot.row[0] / np.where(slot.row[1] != 0, slot.row[1], np.nan)
    places = [((), [slot.expr], 0, True)]
    places += [(p, t, i, False) for p, t in sums(slot.expr) for i in range(len(t))]
    for path, terms, i, whole in places:
        term = terms[i]
        if whole or _affine(slot.expr, path):
            without = sp.S.Zero if whole else with_term(slot.expr, path, terms, i, None)
            base = evaluate(without, slot.symbols)
            part = slot.values - base
            target = goal - base
            if slot.centred:
                part, target = part - np.mean(part), target - np.mean(target)
            ok = np.isfinite(target) & np.isfinite(part)
            denominator = float(np.dot(part[ok], part[ok]))
            k = _nice(float(np.dot(part[ok], target[ok]) / denominator)) if denominator > 0 else None
            tried = [k] if k is not None else []
        else:
            tried = list(COEFFICIENTS)
        for k in tried:
            factor = sp.Rational(k.numerator, k.denominator)
            new = factor * term
            expr = new if whole else with_term(slot.expr, path, terms, i, new)
            operator = {0: "drop", -1: "sign"}.get(k, "scale")
            out.append(Edit(operator, term, new, expr, f"{term} → {new}"))
    return out


#: the kinds of parameter an added term of each quantity may hold (its units): friction only in
#: D, gravity only in H and V
KINDS_OF = {
    "D": {"damping"},
    "H": {"mass", "length", "offset", "gravity", "inertia", ""},
    "V": {"mass", "length", "offset", "gravity", "inertia", ""},
}
OTHER_KINDS = {"mass", "length", "offset", "inertia", ""}


def _monomials(sm: SymbolicModel, params: dict, quantity: str) -> tuple[list, list]:
    """(value, expression) of the parameter products an added term may hold: first those the
    model's own terms hold (the parameter part of each term of its written forms), then every
    product of at most ``DEGREE`` parameters of the kinds the quantity allows (``KINDS_OF``)."""
    kinds = {p.name: k for p, k in zip(sm.parameters.values(), _kind_list(sm), strict=True)}
    allowed = KINDS_OF.get(quantity, OTHER_KINDS)
    symbols = [s for s in sm.parameters.values() if kinds[s.name] in allowed]
    own: dict = {}
    for value in sm.closed_forms.values():
        for expr in entries(value):
            for _, terms in sums(expr):
                for term in terms:
                    factor = sp.Mul(*[f for f in sp.Mul.make_args(term) if f.free_symbols <= set(symbols)])
                    factor = factor.as_coeff_Mul()[1]
                    if factor.free_symbols:
                        own[factor] = None
    generic = [
        sp.Mul(*combo)
        for degree in range(1, DEGREE + 1)
        for combo in itertools.combinations_with_replacement(symbols, degree)
    ]
    values = {sm.parameters[p]: v for p, v in params.items()}
    out: tuple[list, list] = ([], [])
    for group, exprs in zip(out, (list(own), generic), strict=True):
        for expr in exprs:
            value = float(expr.xreplace(values))
            if value != 0 and np.isfinite(value):
                group.append((value, expr))
    return out


def _kind_list(sm) -> list[str]:
    return [f.metadata.get("kind", "") for f in dataclasses.fields(sm.cls.params_type)]


FRACTIONS = tuple(
    Fraction(a, b) for b in (1, 2, 3, 4, 6, 12) for a in range(1, 5) if Fraction(a, b).denominator == b
)


PAIR_FACTORS = (1, -1, 2, -2, sp.Rational(1, 2), -sp.Rational(1, 2))


def _matched(coefficient: float, monomials) -> sp.Expr | None:
    """coefficient as ± a simple fraction times a product of parameters, or as a sum of two such
    (factors ±1, ±2, ±½), the simplest such; None when none equals it to 1e-9."""
    close = 1e-9 * abs(coefficient)
    for whole in (True, False):  # a product as it stands before one with a fraction
        for value, expr in monomials:
            ratio = Fraction(abs(coefficient) / value).limit_denominator(12)
            if (
                (ratio == 1) is whole
                and ratio in FRACTIONS
                and abs(float(ratio) * value - abs(coefficient)) <= close
            ):
                return sp.sign(coefficient) * sp.Rational(ratio.numerator, ratio.denominator) * expr
    values = np.array([v for v, _ in monomials])
    order = np.argsort(values)
    ordered = values[order]
    for f1, f2 in itertools.product(PAIR_FACTORS, repeat=2):
        rest = (coefficient - float(f1) * values) / float(f2)  # what the second monomial must be
        at = np.clip(np.searchsorted(ordered, rest), 1, len(ordered) - 1)
        for k in np.flatnonzero(np.minimum(abs(ordered[at] - rest), abs(ordered[at - 1] - rest)) <= close):
            j = order[at[k]] if abs(ordered[at[k]] - rest[k]) <= close else order[at[k] - 1]
            if j != k:
                return f1 * monomials[k][1] + f2 * monomials[j][1]
    return None


def _added_term_edits(slot: Slot, batch, monomials) -> list[Edit]:
    """The entry's difference fitted and written as parameters times basis functions (module
    docstring).  For a Coriolis row the entry's share q̇j·Δ of the row's residual is fitted, with
    Δ in the basis of C."""
    quantity = QUANTITY.get(slot.method, "C" if slot.row is not None else None)
    if quantity not in ("M", "H", "V", "D", "detM", "Cqdot", "C"):
        return []
    model = batch.model
    basis = basis_for(quantity, batch.Q, batch.V, model.angular, model.coordinates)
    if slot.row is None:
        diff = slot.target - slot.values
    else:
        residual, rate = slot.row
        basis = [(name, values * rate, expr) for name, values, expr in basis]
        diff = -residual
    pattern = fit(diff, basis)
    if pattern is None:
        return []
    added = []
    for (c, name), function in zip(pattern.terms, pattern.functions, strict=True):
        if slot.centred and name == "1":  # V is compared up to a constant
            continue
        own, generic = monomials  # the model's own products alone first, then with every other
        monomial = _matched(c, own) or _matched(c, own + generic)
        if monomial is None:
            return []
        added.append(monomial * function)
    term = sp.Add(*added)
    return [Edit("add", sp.S.Zero, term, slot.expr + term, f"add {term}")]


def sum_pool(sm: SymbolicModel) -> list[frozenset]:
    """The sums written anywhere in the model's closed forms, each as the set of its terms."""
    pool = set()
    for value in sm.closed_forms.values():
        for expr in entries(value):
            pool |= {frozenset(node.args) for node, _ in walk(expr) if node.is_Add}
    return sorted(pool, key=len)


def _restored_term_edits(slot: Slot, pool) -> list[Edit]:
    """A sum (or a lone term) completed by the one term it lacks, as the same sum stands elsewhere
    in the model: the inverse of a term dropped inside a factor (det M, M⁻¹)."""
    out = []
    for node, path in walk(slot.expr):
        terms = frozenset(node.args) if node.is_Add else frozenset([node])
        if node.is_Number:
            continue
        for other in pool:
            if len(other) == len(terms) + 1 and terms < other:
                new = sp.Add(*other)
                added = next(iter(other - terms))
                out.append(
                    Edit("drop", node, new, replace_at(slot.expr, path, new), f"add {added} to {node}")
                )
    return out


def _screen(slot: Slot, batch, sm, evaluate, monomials, pool, deadline: float) -> None:
    kinds = {sm.parameters[f.name]: f.metadata.get("kind", "") for f in _fields(sm)}
    edits = _coefficient_edits(slot, evaluate) + _added_term_edits(slot, batch, monomials)
    edits += _restored_term_edits(slot, pool)
    edits += list(structural_edits(slot.expr, sm.angles, sm.symbols["v"], kinds))
    seen = set()
    allowed = set(sm.flat_arguments(slot.symbols)) | set(sm.parameters.values())
    for edit in edits:
        if time.perf_counter() > deadline:
            return
        if edit.expr in seen or edit.expr == slot.expr or not edit.expr.free_symbols <= allowed:
            continue
        seen.add(edit.expr)
        values = evaluate(edit.expr, slot.symbols)
        if np.all(np.isfinite(values)) and slot.mismatch(values) <= SCREEN_RTOL:
            slot.matches.append(edit)


def _fields(sm):
    return dataclasses.fields(sm.cls.params_type)


#: the order candidates are confirmed in, simplest first: a factor 2 or ½ comes after the edits
#: that change a symbol, so that a parameter swapped for one worth twice as much (mc = 2·mp) is
#: put back as the swap, not as a factor
RANK = {
    "sign": 0,
    "drop": 1,
    "swap θ": 2,
    "swap θ̇": 2,
    "parameter": 2,
    "sin↔cos": 3,
    "scale": 4,
    "offset": 5,
    "add": 6,
}


def _candidates(slots: list[Slot]) -> list[tuple[int, dict, Edit, Slot]]:
    """(rank, {(method, index): (old, new)}, the edit shown, its slot), simplest first."""
    out = []
    for slot in slots:
        for edit in slot.matches:
            local = {(slot.method, slot.index): (slot.expr, edit.expr)}
            out.append((RANK.get(edit.operator, 9), local, edit, slot))
            shared = dict(local)
            for other in (
                s for s in slots if s is not slot
            ):  # the same edit where the same expression stands
                if other.expr == slot.expr:
                    shared[(other.method, other.index)] = (other.expr, edit.expr)
                elif not edit.old.is_Atom and other.expr.has(edit.old):
                    shared[(other.method, other.index)] = (other.expr, other.expr.subs(edit.old, edit.new))
            if len(shared) > 1:
                out.append((10 + RANK.get(edit.operator, 9), shared, edit, slot))
    if len(slots) == 2 and not any(len(c) == 2 for _, c, _, _ in out):
        a, b = slots
        for ea, eb in itertools.islice(itertools.product(a.matches, b.matches), MAX_PAIRS):
            changes = {(a.method, a.index): (a.expr, ea.expr), (b.method, b.index): (b.expr, eb.expr)}
            out.append((20 + RANK.get(ea.operator, 9) + RANK.get(eb.operator, 9), changes, ea, a))
    return sorted(out, key=lambda c: c[0])


def _confirmed(batch, sm, changes: dict) -> bool:
    edits: dict[str, list] = {}
    for (method, index), (old, new) in changes.items():
        edits.setdefault(method, []).append((index, old, new))
    repaired = edited_model(batch.model, sm, edits, "Repaired")
    names = applicable_checks(repaired, batch.system)
    with np.errstate(all="ignore"):
        try:
            results = run_checks("repair", repaired, batch.system, batch.states, 0, names)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):
            return False
    return all(r.passed for r in results)


def search_repair(batch, deadline_s: float) -> tuple[list[Finding], str]:
    """The confirmed repair of a failing model as findings, and what the search did, in words."""
    start = time.perf_counter()
    deadline = start + deadline_s
    try:
        sm = SymbolicModel.of(type(batch.model))
        forms = sm.closed_forms
    except Exception as exc:
        return [], f"no repair searched: SymPy cannot read the model ({type(exc).__name__})"
    screen = batch.subset(range(min(SCREEN_STATES, len(batch))))
    params = {p: float(getattr(batch.model.params, p)) for p in sm.parameters}
    evaluate = _evaluator(
        sm, {"q": screen.Q, "v": screen.V, "u": screen.U, "w": screen.W}, list(params.values())
    )
    slots = find_slots(screen, sm)
    if not slots:
        return [], "no single entry of the written closed forms disagrees with Pinocchio: no repair searched"
    pool = sum_pool(sm)
    monomials: dict[str, list] = {}
    for slot in slots:
        quantity = QUANTITY.get(slot.method, "")
        if quantity not in monomials:
            monomials[quantity] = _monomials(sm, params, quantity)
        _screen(slot, screen, sm, evaluate, monomials[quantity], pool, deadline)
    notation = Notation.of(type(batch.model))
    tried, found, seen = 0, [], set()
    for rank, changes, edit, slot in _candidates(slots):
        if time.perf_counter() > deadline or tried >= CONFIRMATIONS or len(found) > ALTERNATIVES:
            break
        if found and rank > RANK["scale"]:
            break  # an alternative is a simple edit, not a shift or a fitted term that happens to fit
        key = tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))
        if key in seen or (found and set(changes) != set(found[0][0])):
            continue  # the same edit again, or (once one is found) an edit of other entries
        seen.add(key)
        tried += 1
        if _confirmed(batch, sm, changes):
            found.append((changes, edit, slot))
    if found:
        findings = _findings(*found[0], forms, notation)
        for changes, edit, slot in found[1:]:
            findings += _findings(changes, edit, slot, forms, notation, alternative=True)
        return findings, ""
    where = ", ".join(s.label for s in slots[:6]) + (f" and {len(slots) - 6} more" if len(slots) > 6 else "")
    bound = " (the search stopped at its time bound)" if time.perf_counter() > deadline else ""
    return [], (
        f"no repair: no single edit of {where} (nor a pair, for two entries) makes every check pass; "
        f"{tried} candidate(s) tried against every check{bound}"
    )


def _findings(changes: dict, edit: Edit, slot: Slot, forms: dict, notation, alternative: bool = False):
    """The ``repair`` findings of one confirmed edit (one per entry it changes)."""
    out = []
    for (method, index), (old, new) in changes.items():
        label = _label(method, forms[method], index)
        written, suggested = notation.render(old), notation.render(new)
        location = notation.location(method, label)
        shown = (
            f"{written} → {suggested}"
            if len(written) + len(suggested) <= 160
            else f"{notation.render(edit.old)} → {notation.render(edit.new)} in {label}"
        )
        message = f"{label}: {shown} makes every check pass on every state ({location})"
        if alternative:
            message = (
                f"or, equally: {message} (with these parameter values the checks cannot tell the two apart)"
            )
        quantity = QUANTITY.get(method)
        value = forms[method]
        if isinstance(value, sp.MatrixBase):
            r, c = divmod(index, value.shape[1])
            position = (r + 1,) if value.shape[1] == 1 else (r + 1, c + 1)
        else:
            position = ()
        out.append(
            Finding(
                "repair",
                message,
                quantity,
                position,
                {
                    "written": str(old),
                    "suggested": str(new),
                    "suggested_source": suggested,
                    "location": location,
                    "checks_pass": True,
                },
            )
        )
    return out
