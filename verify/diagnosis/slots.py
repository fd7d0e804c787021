"""Where a repair is needed: the entries of the written closed forms that disagree with Pinocchio.

The model's written closed forms are read as SymPy expressions
(``pendverify.analytic.symbolic_reading``) and each entry is evaluated at the screening states
(the first ``SCREEN_STATES`` judged states, special ones first; ``evaluator``, vectorised over
them) next to what it must equal there according to Pinocchio (``targets``): M, H, det M,
M⁻¹, q̈, C·q̇ directly; V up to a constant (both centred); D the URDF's where it declares
damping; a Coriolis-type matrix (C, or C + D) through its rows' product with q̇, since C
itself is not unique; a form beyond the interface through what it ``equals``.  An entry whose
values differ by more than ``SCREEN_RTOL`` of its quantity's size is a *slot* to repair.

B, W (and D where the URDF declares no damping) have no counterpart in Pinocchio; what they
must be follows from the hand model's own q̈: M_pin·q̈_hand + bias_pin = B u + W w − D q̇ at
every state, a linear regression of the left side on (u, w, −q̇) (``_force_matrices``).  When
it is exact (relative residual within ``SCREEN_RTOL``: everything else the hand model says is
Pinocchio's) its matrices are B's, W's and D's targets, so that an error in B is found in B
and not only where q̈ uses it.

Screening tolerance: a right entry and Pinocchio's value differ by rounding, a few ε of the
terms' size times the cancellation; ``SCREEN_RTOL`` = 1e-7 of the quantity's size leaves a
margin of 1e8 ε for that and is still far below any edit (a 1e-3 scale changes a term by
1e-3 of itself).  It only selects candidates: the checks decide (``pendverify.diagnosis.repair``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel, entries

SCREEN_STATES = 24
SCREEN_RTOL = 1e-7  # (module docstring)
#: each interface method's quantity, as ``diagnoses`` in the JSON report names it
QUANTITY = {
    "mass_matrix": "M",
    "coriolis_matrix": "C",
    "coriolis_force": "Cqdot",
    "gravity": "H",
    "potential_energy": "V",
    "damping_matrix": "D",
    "input_matrix": "B",
    "disturbance_matrix": "W",
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


@functools.lru_cache(maxsize=8192)
def compiled(symbols: tuple, expr):
    """``expr`` as a NumPy function of ``symbols``, kept for the process: a repair search meets the
    same entries and edits again (each planted error of ``bench explain`` has the others' entries)."""
    return sp.lambdify(symbols, expr, modules="numpy", docstring_limit=0)


_FUNCTIONS = {sp.sin: np.sin, sp.cos: np.cos, sp.tan: np.tan, sp.exp: np.exp, sp.Abs: np.abs}


class _NodeValues:
    """An expression's values at the screening states, computed node by node with each node's
    values kept: the edits a repair tries change one node of an entry, so an edited entry costs
    the nodes on the path from that node to the root, where compiling it again (``compiled``)
    costs the printing of the whole entry — tens of milliseconds for a q̈ written out in full,
    for each of hundreds of edits.  Sums and products are taken in the order of the node's
    arguments; the values differ from the compiled function's by rounding only."""

    def __init__(self, values: dict, n: int):
        self.values = dict(values)  # symbol → its values at the states
        self.n = n

    def __call__(self, node) -> np.ndarray:
        found = self.values.get(node)
        if found is not None:
            return found
        if not node.free_symbols:  # a number; one that is not real (zoo from an edit's 1/0) is nan
            try:
                value = np.full(self.n, float(node))
            except TypeError:
                value = np.full(self.n, np.nan)
        elif node.is_Add:
            value = functools.reduce(np.add, map(self, node.args))
        elif node.is_Mul:
            value = functools.reduce(np.multiply, map(self, node.args))
        elif node.is_Pow:
            value = np.power(self(node.base), self(node.exp))
        elif node.func in _FUNCTIONS:
            value = _FUNCTIONS[node.func](self(node.args[0]))
        else:  # anything else as SymPy prints it
            symbols = tuple(sorted(node.free_symbols, key=str))
            value = compiled(symbols, node)(*(self(s) for s in symbols))
        value = np.broadcast_to(np.asarray(value, dtype=float), (self.n,))
        self.values[node] = value
        return value


def evaluator(sm: SymbolicModel, arrays: dict, params: list):
    """f(expr, args) → the expression's values at the screening states (vectorised, node by node:
    ``_NodeValues``)."""
    n = len(arrays["q"])
    nodes: dict[str, _NodeValues] = {}

    def evaluate(expr, args: str) -> np.ndarray:
        symbols = tuple(sm.flat_arguments(args) + list(sm.parameters.values()))
        columns = [arrays[a][:, k] for a in args for k in range(arrays[a].shape[1])]
        with np.errstate(all="ignore"):
            if expr.free_symbols <= set(symbols):
                if args not in nodes:
                    values = [*columns, *(np.full(n, float(p)) for p in params)]
                    nodes[args] = _NodeValues(dict(zip(symbols, values, strict=True)), n)
                return nodes[args](expr)
            value = compiled(symbols, expr)(*columns, *params)
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


def _force_matrices(batch) -> dict[str, np.ndarray] | None:
    """{method: B, W, D} fitted from M_pin·q̈_hand + bias_pin = B u + W w − D q̇ (module docstring),
    or None when no constant matrices reproduce it (something else is wrong too)."""
    t = batch.terms
    nu, nw = batch.U.shape[1], batch.W.shape[1]
    with np.errstate(all="ignore"):
        force = (t.M_pin @ t.a_hand[:, :, None])[..., 0] + t.bias_pin
    X = np.concatenate([batch.U, batch.W, -batch.V], axis=1)
    if not np.all(np.isfinite(force)) or np.linalg.matrix_rank(X) < X.shape[1]:
        return None
    solution, *_ = np.linalg.lstsq(X, force, rcond=None)
    residual = float(np.max(np.abs(X @ solution - force), initial=0.0))
    if residual > SCREEN_RTOL * (float(np.max(np.abs(force), initial=0.0)) or 1.0):
        return None
    matrices = solution.T  # n × (nu + nw + n)
    return {
        "input_matrix": matrices[:, :nu],
        "disturbance_matrix": matrices[:, nu : nu + nw],
        "damping_matrix": matrices[:, nu + nw :],
    }


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
    forces = _force_matrices(batch)
    if method in ("input_matrix", "disturbance_matrix") or (
        method == "damping_matrix" and not np.any(system.urdf_damping())
    ):
        if forces is None or method not in forces:
            return None, False, False
        value = forces[method]
        return np.broadcast_to(value, (n, *value.shape)), False, False
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


def entry_label(method: str, value, index: int) -> str:
    name = QUANTITY.get(method, method)
    if not isinstance(value, sp.MatrixBase):
        return name
    return f"{name}[{','.join(str(i + 1) for i in entry_position(method, value.shape, index))}]"


def _entry_values(batch, evaluate, method: str, form, flat: list) -> np.ndarray | None:
    """Each entry of ``method``'s written form at the batch's states, (N, entries): as the checks
    evaluate the model's own method (its generated code, built once for the checks) where the model
    writes it, else each entry lambdified.  Printing every entry of a large model for SymPy's
    ``lambdify`` took minutes (a 20-link chain's 400 entries of M: 110 s); the entries that disagree
    are lambdified later all the same, for their edits."""
    if not flat:
        return None
    if method in batch.forms.written:
        with np.errstate(all="ignore"):
            own = np.asarray(batch.forms.value(method), dtype=float)
        if own.size == len(batch) * len(flat):
            return own.reshape(len(batch), len(flat))
    return np.stack([evaluate(e, form.args) for e in flat], axis=-1)


def find_slots(batch, sm: SymbolicModel) -> list[Slot]:
    """Every entry of a written closed form that disagrees with Pinocchio at the screening states."""
    model = batch.model
    params = [float(getattr(model.params, p)) for p in sm.parameters]
    arrays = {"q": batch.Q, "v": batch.V, "u": batch.U, "w": batch.W}
    evaluate = evaluator(sm, arrays, params)
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
        current = _entry_values(batch, evaluate, method, form, flat)
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
                slot = Slot(method, index, entry_label(method, value, index), expr, form.args, values, None,
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
                label = entry_label(method, value, index)
                slots.append(Slot(method, index, label, expr, form.args, values, goal, None, centred, scale))
    return slots
