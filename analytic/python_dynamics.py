"""A model whose dynamics are Python code: ẋ = f(x, u), ẋ = f(t, x, u) or q̈ = qddot(q, v, u).

The right-hand sides ``scipy.integrate.solve_ivp`` users write (and gymnasium's ``_dsdt``)
are a model file too: a ``.py`` file defining ``DYNAMICS`` (the function) and ``DECLARATION``
(what the code does not say), or ``pendverify.check(model=f, declaration={...}, urdf=..., params=...)``.

The declaration has the keys of a SymPy-mechanics declaration
(``pendverify.analytic.text_parse.DECLARATION_KEYS``: ``name``, ``coordinates`` (name →
"angle"/"position", in order), ``inputs``, ``disturbances``, ``parameters`` (name → {kind,
unit}), ``urdf``) and

* ``dynamics``: the signature, ``"f(x, u)"`` (the default), ``"f(t, x, u)"`` or
  ``"qddot(q, v, u)"``;
* ``state`` (the f forms only): the names of x's entries in order, each a coordinate or its
  rate ``d<coordinate>``; default the coordinates, then their rates: x = (q, q̇), ẋ = (q̇, q̈).
  ẋ has x's layout.  Gymnasium's cart-pole state is ``["x", "dx", "theta", "dtheta"]``;
* ``B`` (required with inputs), ``D``, ``W``: the input, damping and disturbance matrices as
  a text model writes them (SymPy syntax in the parameters, read without running code):
  Pinocchio's ABA needs the generalised force τ = B u + W w − D q̇ the code applies.

How the function is called: ``f(x, u, **parameters)`` (``f(0.0, x, u, **parameters)``,
``qddot(q, v, u, **parameters)``) with NumPy float arrays, u the inputs followed by the
disturbances, and each declared parameter a keyword argument by its name (so gymnasium's
``self.masspole`` becomes a parameter ``masspole``; ``**p`` takes them all).  The gravity
parameter must be named ``g``: Pinocchio's gravity is set from it.  The dynamics
are taken time-invariant: t is 0.  Whether it can be called so is checked when the model is
made (``inspect.Signature.bind``), so a mismatch is one line, not an error at a state.

What becomes of it: a ``PythonDynamicsModel``, an ``AccelerationOnlyModel`` whose q̈ calls the
function.  At each state it evaluates, the entries of ẋ that are the coordinates' rates must be
the state's q̇ (a copy, or a few roundings of one: within ``RATE_ULPS`` ε of |q̇|), else it
refuses with that state; q̈ is the rest.  The code is evaluated numerically only (``numeric_only``):
SymPy does not read it (``pendverify show``, ``sympy``, ``mutate`` refuse in one line), the checks
call it state by state rather than as generated NumPy, and a failing state is not judged again
in high precision (code written with ``math``/NumPy functions would round to double anyway).

With as many inputs as coordinates and B invertible, M, H and C·q̇ are derived numerically at
each state the checks evaluate (``DerivedPythonDynamicsModel``,
``pendverify.analytic.numeric_derivation``: M = B (∂q̈/∂u)⁻¹ from differences, q̈ being affine
in u, H = −M q̈(q, 0, 0), C·q̇ = −M (q̈(q, q̇, 0) − q̈(q, 0, 0)) − D q̇), so ``crba``, ``gravity``
and ``rnea`` run too, each with the derivation's rounding bound added to its tolerance; V
(``energy``), a matrix C (``coriolis``, ``skew``), det M and M⁻¹ (``det``, ``minverse``) are
numbers at states, not closed forms, and are not checked.  With fewer inputs M is not
determined: only ``aba`` (and ``damping``) run, and the report says why the others do not.
An exception the function raises is one line naming its
file and line and the exception (``UserCodeError``).
"""

from __future__ import annotations

import inspect
import traceback
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import ClassVar

import numpy as np

from pendverify.analytic.forms import NUMERIC_MATH
from pendverify.analytic.interface import AccelerationOnlyModel
from pendverify.analytic.numeric_derivation import DERIVED, NumericDerivation, derive
from pendverify.display import shortened
from pendverify.errors import PendverifyError, UserCodeError

#: the signatures a right-hand side may have, each with the positional arguments pendverify passes
SIGNATURES = {"f(x, u)": ("x", "u"), "f(t, x, u)": ("t", "x", "u"), "qddot(q, v, u)": ("q", "v", "u")}
#: the keys of a Python dynamics declaration beyond a SymPy-mechanics declaration's
EXTRA_KEYS = ("dynamics", "state")
#: the matrices a declaration writes as text
MATRIX_KEYS = ("B", "D", "W")
#: ẋ's rate entries may differ from q̇ by this many ε of |q̇|: a copy is exact, and an expression
#: that equals q̇ (1.0 * v, v + 0.0, a unit conversion there and back) rounds once or twice
RATE_ULPS = 4
#: why the model's code is evaluated numerically only (``ClosedFormModel.numeric_only``)
NUMERIC_ONLY = "its q̈ is Python code (DYNAMICS), evaluated numerically only, not read by SymPy"


class PythonDynamicsModel(AccelerationOnlyModel):
    """An ``AccelerationOnlyModel`` whose q̈ is a Python function's (module docstring).

    A model made by ``python_dynamics_model`` sets ``dynamics`` (the function), ``signature``
    (a key of ``SIGNATURES``), ``positions`` and ``rates`` (where q and q̇ sit in x and ẋ) and
    ``source`` (the function's file, for messages).
    """

    numeric_only: ClassVar[str] = NUMERIC_ONLY
    without_mass_matrix: ClassVar[str] = (
        "its inputs do not span the coordinates (∂q̈/∂u = M⁻¹B is not square), so M, C·q̇, H and V "
        "are not determined from its code"
    )
    dynamics: ClassVar[Callable]
    signature: ClassVar[str] = "f(x, u)"
    positions: ClassVar[tuple[int, ...]] = ()
    rates: ClassVar[tuple[int, ...]] = ()
    source: ClassVar[str] = "<declaration>"

    def acceleration(self, q, v, u, w):
        if self.math is not NUMERIC_MATH:  # read by SymPy, mpmath or complex step: not this code
            raise TypeError(NUMERIC_ONLY)
        q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
        forces = np.concatenate([np.asarray(u, dtype=float), np.asarray(w, dtype=float)])
        if self.signature == "qddot(q, v, u)":
            return self._returned(self._call(q.copy(), v.copy(), forces), self.nv, q, v, forces)
        x = np.empty(2 * self.nv)
        x[list(self.positions)], x[list(self.rates)] = q, v
        args = (x, forces) if self.signature == "f(x, u)" else (0.0, x, forces)
        xdot = self._returned(self._call(*args), 2 * self.nv, q, v, forces)
        rate = xdot[list(self.positions)]
        if not np.all(np.abs(rate - v) <= RATE_ULPS * np.finfo(float).eps * np.abs(v)):
            raise UserCodeError(
                self.source,
                f"{self._name()} returned ẋ whose entries for the coordinates' rates are {rate.tolist()}, "
                f"not q̇ = {v.tolist()} (at q = {q.tolist()}, u = {forces.tolist()}): ẋ must be "
                "(q̇, q̈) in the declared state layout",
            )
        return xdot[list(self.rates)]

    def _name(self) -> str:
        arguments = self.signature[self.signature.index("(") :]
        return f"DYNAMICS {getattr(self.dynamics, '__name__', 'function')}{arguments}"

    def _call(self, *args):
        try:
            return self.dynamics(*args, **self.params.as_dict())
        except KeyboardInterrupt:
            raise
        except Exception as exc:
            frames = [
                f for f in traceback.extract_tb(exc.__traceback__) if _resolved(f.filename) == self.source
            ]
            place = f"{self.source}, line {frames[-1].lineno}" if frames else self.source
            state = ", ".join(f"{n} = {shortened(str(np.asarray(a).tolist()), 120)}" for n, a in zip(
                SIGNATURES[self.signature], args, strict=True))  # fmt: skip
            raise UserCodeError(
                place, f"{self._name()} raised {type(exc).__name__}: {shortened(str(exc), 200)} (at {state})"
            ) from None

    def _returned(self, value, size: int, q, v, forces) -> np.ndarray:
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError) as exc:
            array, why = None, f"({type(exc).__name__}: {exc})"
        else:
            why = f"an array of shape {array.shape}"
        if array is None or array.shape != (size,):
            raise UserCodeError(
                self.source,
                f"{self._name()} must return {size} numbers; it returned {shortened(why, 120)} "
                f"at q = {q.tolist()}, q̇ = {v.tolist()}, u = {forces.tolist()}",
            )
        return array


class DerivedPythonDynamicsModel(PythonDynamicsModel):
    """A ``PythonDynamicsModel`` with B square and invertible: M, H and C·q̇ derived from its q̈.

    Each is derived at the configurations the checks evaluate, once per configuration
    (``pendverify.analytic.numeric_derivation``); q̈ stays the code's own, checked by aba.
    """

    mass_from_acceleration: ClassVar[str] = DERIVED

    def _derived(self, q) -> NumericDerivation:
        q = np.asarray(q, dtype=float)
        cache = self.__dict__.setdefault("_derivations", {})
        key = q.tobytes()
        if key not in cache:

            def fail(message: str):
                raise UserCodeError(self.source, f"{self._name()}: {message}")

            B = np.asarray(self.input_matrix(), dtype=float)
            if not np.isfinite(np.linalg.cond(B)) or np.linalg.cond(B) * np.finfo(float).eps >= 1:
                fail(f"B = {B.tolist()} is singular at these parameters: M = B (∂q̈/∂u)⁻¹ cannot be formed")
            cache[key] = derive(self.acceleration, q, B, len(self.disturbances), fail)
        return cache[key]

    def derivation_steps(self, q) -> np.ndarray:
        """The steps h of the inputs the derivation at q took (``numeric_derivation.rounding_bounds``)."""
        return self._derived(q).steps

    def mass_matrix(self, q):
        return self._derived(q).M

    def gravity(self, q):
        found = self._derived(q)
        return -found.M @ found.rest

    def _moving(self, q, v) -> np.ndarray:
        """q̈(q, q̇, 0, 0)."""
        n = self.nv
        return np.asarray(self.acceleration(q, v, np.zeros(n), np.zeros(len(self.disturbances))), dtype=float)

    def coriolis_force(self, q, v):
        found, v = self._derived(q), np.asarray(v, dtype=float)
        D = np.asarray(self.damping_matrix(), dtype=float)
        return -found.M @ (self._moving(q, v) - found.rest) - D @ v

    def bias(self, q, v):
        found, v = self._derived(q), np.asarray(v, dtype=float)
        D = np.asarray(self.damping_matrix(), dtype=float)
        return -found.M @ self._moving(q, v) - D @ v


def _resolved(filename: str) -> str:
    try:
        return str(Path(filename).resolve())
    except (OSError, ValueError):  # pragma: no cover - a frame of a file that is gone
        return filename


def _function_file(function) -> str:
    try:
        found = inspect.getsourcefile(function)
    except TypeError:  # a builtin or a C function: no Python source
        found = None
    return _resolved(found) if found else "<declaration>"


def _layout(fail, declaration: Mapping, coordinates: tuple[str, ...]) -> tuple[tuple[int, ...], ...]:
    """(positions, rates): where each coordinate and each rate sits in x (``state``, docstring)."""
    default = [*coordinates, *(f"d{c}" for c in coordinates)]
    state = declaration.get("state", default)
    if (
        not isinstance(state, list | tuple)
        or not all(isinstance(s, str) for s in state)
        or sorted(state) != sorted(default)
    ):
        fail(
            "state",
            f"must list x's entries, each of {', '.join(default)} once; got {shortened(repr(state), 80)}",
        )
    state = list(state)
    return tuple(state.index(c) for c in coordinates), tuple(state.index(f"d{c}") for c in coordinates)


def python_dynamics_model(function, declaration: Mapping, source: str | Path | None = None, module=None):
    """The ``PythonDynamicsModel`` class of a right-hand side and its declaration (module docstring).

    ``source`` names the declaration in messages (a model file; default ``<declaration>``);
    ``module``: the model file's module the class is to live in.  Raises ``PendverifyError``.
    """
    # deferred on purpose: SymPy (the text reader of B, D, W) loads only for such a model
    from pendverify.analytic.text_model import build_model_class
    from pendverify.analytic.text_parse import DECLARATION_KEYS, Reader, read_text_document

    path = Path(str(source if source is not None else "<declaration>"))
    reader = Reader(path)
    if not isinstance(declaration, Mapping):
        reader.fail("declaration", "must be a mapping of name, coordinates, inputs, parameters and urdf")
    if not callable(function) or isinstance(function, type):
        reader.fail("DYNAMICS", f"must be a function; got a {type(function).__name__}")
    data = {k: v for k, v in declaration.items() if k not in EXTRA_KEYS}
    spec = read_text_document(path, data, (*DECLARATION_KEYS, *MATRIX_KEYS))
    signature = declaration.get("dynamics", "f(x, u)")
    if signature not in SIGNATURES:
        reader.fail("dynamics", f"{shortened(repr(signature), 60)}: must be one of {', '.join(SIGNATURES)}")
    if "state" in declaration and signature == "qddot(q, v, u)":
        reader.fail("state", "goes with f(x, u) or f(t, x, u); qddot(q, v, u) takes q and q̇ apart")
    require_gravity_named_g(reader, spec)
    positions, rates = _layout(reader.fail, declaration, spec.coordinates)
    if spec.inputs and "B" not in spec.equations:
        reader.fail("B", f"missing: the model declares inputs {', '.join(spec.inputs)}")
    for key in MATRIX_KEYS:
        value = spec.equations.get(key)
        if value is not None and value.free_symbols - set(spec.symbols["p"]):
            reader.fail(key, "must depend on the parameters only (it is constant over states)")
    try:
        inspect.signature(function).bind(*SIGNATURES[signature], **dict.fromkeys(spec.parameters, 0.0))
    except TypeError as exc:
        reader.fail(
            "dynamics",
            f"{getattr(function, '__name__', 'DYNAMICS')} cannot be called as {signature[:-1]}, "
            f"{', '.join(f'{p}=…' for p in spec.parameters) or 'no parameters'}): {exc}",
        )
    except ValueError:  # no signature to read (a builtin): it is called as declared and answers then
        pass
    cls = build_model_class(spec, module, base=_base(spec))
    cls.dynamics = staticmethod(function)
    cls.signature, cls.positions, cls.rates = signature, positions, rates
    cls.source = _function_file(function)
    return cls


def require_gravity_named_g(reader, spec) -> None:
    """A declared parameter of kind gravity must be named g: Pinocchio's gravity is set from ``g``."""
    for name, (kind, _) in spec.parameters.items():
        if kind == "gravity" and name != "g":
            reader.fail(f"parameters.{name}", "name the gravity g: Pinocchio's gravity is taken from g")


def _base(spec) -> type[PythonDynamicsModel]:
    """``DerivedPythonDynamicsModel`` where B is square and invertible (for all parameters but
    those that zero det B), else ``PythonDynamicsModel``."""
    B = spec.equations.get("B")
    if B is not None and B.rows == B.cols == len(spec.coordinates) and B.det() != 0:
        return DerivedPythonDynamicsModel
    return PythonDynamicsModel


def model_file_dynamics(module, path: Path):
    """The model class a Python model file declares by ``DYNAMICS`` and ``DECLARATION``, or None."""
    if not hasattr(module, "DYNAMICS"):
        return None
    if hasattr(module, "METHOD"):
        raise PendverifyError(f"{path}: defines both DYNAMICS and METHOD; a model file gives one of them")
    if not hasattr(module, "DECLARATION"):
        raise PendverifyError(
            f"{path}: defines DYNAMICS but no DECLARATION (its coordinates, parameters, inputs, B, urdf)"
        )
    return python_dynamics_model(module.DYNAMICS, module.DECLARATION, path, module)
