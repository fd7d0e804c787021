"""A model given as plain NumPy functions of the state and a parameter object ``p``.

A Python model file may define, instead of a class, the parts of

    M(q) q̈ + C(q, q̇) q̇ + D q̇ + G(q) = B u + W w

as functions, written with NumPy as it is (``np.cos``, ``np.array``, ``@``)::

    M(q, p)          the mass matrix, n × n                                  (required)
    C(q, v, p)       the Coriolis/centrifugal matrix C(q, q̇), n × n, friction excluded
    Cqdot(q, v, p)   or the vector C(q, q̇)·q̇, n entries
    h(q, v, p)       or the vector h(q, q̇) = C(q, q̇)·q̇ + G(q), n entries: every term of the
                     left-hand side but M q̈ and the friction D q̇ (what Pinocchio's
                     rnea(q, q̇, 0) returns; many textbooks write M q̈ + h = τ)
    G(q, p)          the gravity vector G(q) = ∂V/∂q, n entries (required, except with h:
                     then G(q) = h(q, 0))
    V(q, p)          the potential energy, a number (optional: the ``energy`` check needs it)
    D(p), B(p), W(p) the friction, input and disturbance matrices, n × n, n × inputs,
                     n × disturbances (D and W optional, zero; B required with inputs)
    det_M(q, p)      det M(q), a number (optional: the ``det`` check compares it with M's)
    qddot(q, v, u, w, p)  q̈, n entries, u the inputs and w the disturbances as arrays
                     (optional: the ``aba`` check compares it with Pinocchio's; a model of q̈
                     alone is ``DYNAMICS`` with ``"dynamics": "qddot(q, v, u)"``,
                     ``pendverify.analytic.python_dynamics``)

exactly one of C, Cqdot and h; with ``DECLARATION``, the mapping a ``sympy.physics.mechanics``
model file declares (``pendverify.analytic.text_parse.DECLARATION_KEYS``: ``name``,
``coordinates`` (name → "angle"/"position", in order), ``inputs``, ``disturbances``,
``parameters`` (name → {kind, unit}), ``urdf`` (joints, transform, offset)), and optionally
``PARAMS``, a dict of the parameters' values used when no parameter file is named
(``--params`` wins over it).

``p`` gives each declared parameter by attribute and by key (``p.m``, ``p["m"]``), as a float;
q and v are NumPy float arrays (copies: a function may change them).  The gravity parameter must
be named ``g``: Pinocchio's gravity is set from it.

What becomes of it: a ``NumpyFunctionModel`` (a ``ClosedFormModel``; with Cqdot or h a
``BiasOnlyModel``, so ``coriolis`` and ``skew`` are not run) whose methods call the functions and
check what each returns: a wrong shape or an exception is one line naming the file (and line)
and the state.  Each function's signature is checked when the model is made
(``inspect.Signature.bind``), so a function that cannot be called as documented is refused at once.
The functions are evaluated numerically only (``numeric_only``): SymPy does not read them
(``show``, ``sympy``, ``mutate`` refuse in one line), the checks call them state by state, and a
failing state is not judged again in high precision.  det M and M⁻¹ are derived from M (not
checked) unless ``det_M`` gives it; q̈ is derived from the parts (``aba`` checks their composition)
unless ``qddot`` gives it (``aba`` then checks the given q̈).

The tolerance scales a closed form gets as Σ|terms| (``pendverify.analytic.derived_scales``) are
taken here from the functions' values on a grid of configurations (``GRID`` points over [−π, π)
per angle, positions at zero; beyond ``GRID_ANGLES`` angles the same number of seeded random
configurations): the diagonal scale S_i = max |M_ii| and the gravity scale max |G_i| over the grid.
M_ii and G_i of a chain of rigid bodies are sums of products of sinusoids of the angles.
Σ|terms| bounds their maximum from above; where the terms are cosines of sums of angles (the
double pendulum's α + 2β cos θ2, its g(a cos θ1 + b cos(θ1 + θ2))) the maximum equals Σ|terms| at
angles 0, a grid point; a single sinusoid a cos(θ − φ) reaches at least cos(π/GRID) ≈ 0.92 of its
|a| on the grid; where terms of different phases add (cos θ + sin θ) the grid's largest value is
the size the function reaches (√2, not Σ|terms| = 2).  Either way it is the size of the terms that
the relative errors are measured against, as Σ|terms| is for a closed form.
"""

from __future__ import annotations

import inspect
import traceback
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from pendverify.analytic.forms import NUMERIC_MATH
from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel
from pendverify.display import shortened
from pendverify.errors import PendverifyError, UserCodeError

#: function name → (its arguments before p, the shape of its result in "n", "u", "w", the
#: interface method it becomes)
FUNCTIONS: dict[str, tuple[str, str, str]] = {
    "M": ("q", "nn", "mass_matrix"),
    "C": ("qv", "nn", "coriolis_matrix"),
    "Cqdot": ("qv", "n", "coriolis_force"),
    "h": ("qv", "n", "bias"),
    "G": ("q", "n", "gravity"),
    "V": ("q", "", "potential_energy"),
    "D": ("", "nn", "damping_matrix"),
    "B": ("", "nu", "input_matrix"),
    "W": ("", "nw", "disturbance_matrix"),
    "det_M": ("q", "", "det_mass_matrix"),
    "qddot": ("qvuw", "n", "acceleration"),
}
#: the diagnosis's quantities this form names otherwise: the gravity vector is G (given, or h(q, 0))
WRITTEN_NAMES = {"H": "G"}
#: the functions that give the bias, exactly one of which a model file defines
BIAS = ("C", "Cqdot", "h")
#: the grid points per angle, and the most angles gridded (``GRID ** GRID_ANGLES`` points)
GRID = 8
GRID_ANGLES = 4
#: why the model's code is evaluated numerically only (``ClosedFormModel.numeric_only``)
NUMERIC_ONLY = "its M, C, G are NumPy functions (M(q, p), …), evaluated numerically only, not read by SymPy"


def _signature(key: str) -> str:
    """``M(q, p)``, ``D(p)``: how the function ``key`` is called."""
    return f"{key}({', '.join([*FUNCTIONS[key][0], 'p'])})"


def _at(key: str, args: list[np.ndarray]) -> str:
    """ " at q = [...], v = [...]": the state a function ``key`` was called at, for messages."""
    names = FUNCTIONS[key][0]
    return "".join(
        f"{' at' if k == 0 else ','} {n} = {shortened(str(a.tolist()), 120)}"
        for k, (n, a) in enumerate(zip(names, args, strict=True))
    )


class Parameters:
    """The parameters a model's functions receive as ``p``: ``p.m`` and ``p["m"]``, read-only."""

    __slots__ = ("_values",)

    def __init__(self, values: Mapping[str, float]):
        object.__setattr__(self, "_values", dict(values))

    def _missing(self, name: str) -> str:
        return f"no parameter {name!r}; the declared parameters are {', '.join(self._values) or 'none'}"

    def __getattr__(self, name: str) -> float:
        try:
            return self._values[name]
        except KeyError:
            raise AttributeError(self._missing(name)) from None

    def __getitem__(self, name: str) -> float:
        try:
            return self._values[name]
        except KeyError:
            raise KeyError(self._missing(name)) from None

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError("the parameters are read-only")

    def __contains__(self, name: object) -> bool:
        return name in self._values

    def __iter__(self):
        return iter(self._values)

    def __len__(self) -> int:
        return len(self._values)

    def keys(self):
        return self._values.keys()

    def __repr__(self) -> str:
        return f"<parameters {', '.join(f'{k}={v:g}' for k, v in self._values.items())}>"


class NumpyFunctionModel(ClosedFormModel):
    """A model whose parts are NumPy functions of (q, q̇, p) (module docstring).

    A class made by ``numpy_model`` sets ``functions`` (name → function), ``source`` (the model
    file) and ``default_params`` (its ``PARAMS``, or None).
    """

    numeric_only: ClassVar[str] = NUMERIC_ONLY
    functions: ClassVar[dict[str, Callable]] = {}
    source: ClassVar[str] = "<functions>"

    def _p(self) -> Parameters:
        """The parameter object ``p`` of this model's parameter set (made once per set)."""
        cached = self.__dict__.get("_parameters")
        if cached is None or cached[0] is not self.params:
            cached = self.__dict__["_parameters"] = (self.params, Parameters(self.params.as_dict()))
        return cached[1]

    def _evaluate(self, key: str, *arrays) -> np.ndarray:
        """``key``'s function at the state ``arrays`` (q, or q and q̇), its result checked for shape."""
        if self.math is not NUMERIC_MATH:  # read by SymPy, mpmath or complex step: not this code
            raise TypeError(NUMERIC_ONLY)
        args = [np.array(a, dtype=float) for a in arrays]
        try:
            value = self.functions[key](*args, self._p())
        except KeyboardInterrupt:
            raise
        except PendverifyError:
            raise
        except Exception as exc:
            raise UserCodeError(
                _place(exc, self.source),
                f"{_signature(key)} raised {type(exc).__name__}: {shortened(str(exc), 200)}{_at(key, args)}",
            ) from None
        shape = self._shape(key)
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError) as exc:
            got = f"something that is not numbers ({type(exc).__name__}: {shortened(str(exc), 80)})"
        else:
            if array.shape == shape:
                return array
            got = f"an array of shape {array.shape}"
        want = f"an array of shape {shape}" if shape else "a number"
        raise UserCodeError(
            self.source, f"{_signature(key)} must return {want}; it returned {got}{_at(key, args)}"
        )

    def _shape(self, key: str) -> tuple[int, ...]:
        sizes = {"n": self.nv, "u": len(self.inputs), "w": len(self.disturbances)}
        return tuple(sizes[d] for d in FUNCTIONS[key][1])

    def _grid_maximum(self, key: str, values: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """max over the configuration grid (module docstring) of |values(q)|, entry by entry; kept
        under ``key`` for this instance's parameter set."""
        cache = self.__dict__.setdefault("_grid_maxima", {})
        cached = cache.get(key)
        if cached is None or cached[0] is not self.params:
            found = np.max(np.abs([values(q) for q in configuration_grid(self.angular)]), axis=0)
            cached = cache[key] = (self.params, found)
        return cached[1]

    def gravity_scale(self) -> np.ndarray:
        """max |G_i(q)| over the configuration grid (module docstring)."""
        return self._grid_maximum("gravity", self.gravity)

    def diagonal_scale(self, q) -> np.ndarray:
        """max |M_ii(q)| over the configuration grid (module docstring), the same at every q."""
        return self._grid_maximum("diagonal", lambda x: np.diagonal(self.mass_matrix(x))).copy()


class NumpyBiasModel(NumpyFunctionModel, BiasOnlyModel):
    """A ``NumpyFunctionModel`` that gives C·q̇ (``Cqdot``) or the whole bias (``h``), not a matrix C."""


def configuration_grid(angular: tuple[bool, ...]) -> np.ndarray:
    """The configurations the scales are taken over (module docstring), one per row."""
    angular = np.array(angular, dtype=bool)
    k = int(np.count_nonzero(angular))
    points = np.linspace(-np.pi, np.pi, GRID, endpoint=False)
    if k > GRID_ANGLES:
        grid = np.random.default_rng(0).uniform(-np.pi, np.pi, (GRID**GRID_ANGLES, k))
    else:
        grid = np.stack(np.meshgrid(*[points] * k, indexing="ij"), axis=-1).reshape(-1, k)
    Q = np.zeros((len(grid), len(angular)))
    Q[:, angular] = grid
    return Q


def _place(exc: BaseException, source: str) -> str:
    """The model file and the line in it where ``exc`` was raised (the innermost such frame)."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if _resolved(f.filename) == source]
    return f"{source}, line {frames[-1].lineno}" if frames else source


def _resolved(filename: str) -> str:
    try:
        return str(Path(filename).resolve())
    except (OSError, ValueError):  # pragma: no cover - a frame of a file that is gone
        return filename


def _method(key: str):
    def method(self, *arrays):
        return self._evaluate(key, *arrays)

    method.__name__ = FUNCTIONS[key][2]
    method.__doc__ = f"{_signature(key)} of the model file"
    return method


def _h_methods(given_gravity: bool) -> dict[str, Callable]:
    """bias = h(q, q̇); G = h(q, 0) unless G is given; C·q̇ = h(q, q̇) − G(q)."""

    def coriolis_force(self, q, v):
        return self._evaluate("h", q, v) - self.gravity(q)

    namespace: dict[str, Callable] = {"coriolis_force": coriolis_force}
    if not given_gravity:

        def gravity(self, q):
            return self._evaluate("h", q, np.zeros(self.nv))

        namespace["gravity"] = gravity
    return namespace


def numpy_model(
    functions: Mapping[str, Any], declaration: Mapping, source: str | Path, module=None, params=None
):
    """The ``NumpyFunctionModel`` class of a model file's functions, ``DECLARATION`` and ``PARAMS``.

    ``functions``: name → function, the names of ``FUNCTIONS`` the file defines; ``params``: its
    ``PARAMS`` (None: none).  ``module``: the model file's module the class is to live in.
    Raises ``PendverifyError`` naming the file and what is wrong.
    """
    # deferred on purpose: SymPy (the declaration's reader) loads only for such a model file
    from pendverify.analytic.python_dynamics import require_gravity_named_g
    from pendverify.analytic.text_model import class_name_of, declared_attributes, parameter_type
    from pendverify.analytic.text_parse import DECLARATION_KEYS, Reader, read_text_document

    path = Path(str(source))

    def fail(problem: str):
        raise PendverifyError(f"{path}: {problem}")

    reader = Reader(path)
    if not isinstance(declaration, Mapping):
        reader.fail("DECLARATION", "must be a dict of name, coordinates, inputs, parameters and urdf")
    spec = read_text_document(path, dict(declaration), DECLARATION_KEYS)
    require_gravity_named_g(reader, spec)
    for name in spec.parameters:
        if hasattr(Parameters, name):
            reader.fail(f"parameters.{name}", f"p.{name} is taken by the parameter object p; rename it")
    for key, function in functions.items():
        if not callable(function) or isinstance(function, type):
            fail(f"{key} must be a function {_signature(key)}; got a {type(function).__name__}")
        placeholders = [*FUNCTIONS[key][0], "p"]
        try:
            inspect.signature(function).bind(*placeholders)
        except TypeError as exc:
            fail(f"{key} cannot be called as {_signature(key)}: {exc}")
        except ValueError:  # no signature to read (a builtin): it is called as documented and answers then
            pass
    if "M" not in functions:
        fail(
            f"defines {', '.join(functions)} but no M(q, p): a model of NumPy functions gives M(q, p), "
            "C(q, v, p) (or Cqdot(q, v, p) or h(q, v, p)) and G(q, p); a model of q̈ alone is DYNAMICS "
            'with "dynamics": "qddot(q, v, u)" in its DECLARATION'
        )
    bias = [k for k in BIAS if k in functions]
    if len(bias) != 1:
        fail(
            "define exactly one of C(q, v, p) (the matrix C), Cqdot(q, v, p) (the vector C·q̇) and "
            f"h(q, v, p) (C·q̇ + G); it defines {', '.join(bias) if bias else 'none'}"
        )
    if "G" not in functions and "h" not in functions:
        fail("defines no G(q, p), the gravity vector (G = ∂V/∂q; zero without gravity)")
    if spec.inputs and "B" not in functions:
        fail(f"defines no B(p): the declaration declares inputs {', '.join(spec.inputs)}")
    for key, group in (("B", spec.inputs), ("W", spec.disturbances)):
        if key in functions and not group:
            what = "inputs" if key == "B" else "disturbances"
            fail(f"defines {key}(p) but the declaration declares no {what}")
    base = NumpyFunctionModel if "C" in functions else NumpyBiasModel
    class_name = class_name_of(spec)
    params_type = parameter_type(spec, class_name)
    namespace: dict[str, Any] = {
        **declared_attributes(spec, params_type),
        "functions": dict(functions),
        "source": _resolved(str(path)),
        "written_names": WRITTEN_NAMES,
    }
    for key in functions:
        namespace[FUNCTIONS[key][2]] = _method(key)
    if "h" in functions:
        namespace.update(_h_methods("G" in functions))
    cls = type(class_name, (base,), namespace)
    if params is not None:
        if not isinstance(params, Mapping):
            fail(f"PARAMS must be a dict of the parameters' values; got a {type(params).__name__}")
        cls.default_params = params_type.from_mapping(dict(params), str(path), prefix="PARAMS.")
    if module is not None:
        for c in (cls, params_type):
            c.__module__ = module.__name__
            setattr(module, c.__name__, c)
    return cls


def model_file_functions(module, path: Path):
    """The model class a Python model file declares by functions M, C (Cqdot, h), G, … and
    ``DECLARATION``, or None when it defines neither M nor any other of them."""
    functions = {k: getattr(module, k) for k in FUNCTIONS if hasattr(module, k)}
    if not functions:
        if hasattr(module, "DECLARATION"):
            raise PendverifyError(
                f"{path}: defines DECLARATION but no model: give M(q, p), C(q, v, p) and G(q, p) "
                "(NumPy functions), METHOD (a SymPy mechanics derivation) or DYNAMICS (ẋ = f(x, u))"
            )
        return None
    if not hasattr(module, "DECLARATION"):
        raise PendverifyError(
            f"{path}: defines {', '.join(functions)} but no DECLARATION (its coordinates, parameters, "
            "inputs, urdf joints)"
        )
    return numpy_model(functions, module.DECLARATION, path, module, getattr(module, "PARAMS", None))
