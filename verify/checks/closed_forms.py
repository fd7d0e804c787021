"""A model's closed forms at a batch of states: each method evaluated once for all states.

``ClosedForms.value(name)`` is method ``name`` at every state, as a float array with the
batch axis first (``constant(name)`` for a method without arguments); the model's own code is
called through the model boundary (``pendverify.analytic.numeric_values``), which returns each
value as a float array of its shape or refuses it in one line.  How:

* a method the model writes itself is one call of its generated NumPy function
  (``pendverify.numerics.codegen.vectorised``: the model's code read by SymPy and printed
  as elementwise ufuncs over the states);
* a method the model writes itself that SymPy cannot read (a branch on a value, a
  numerical solve), or any method of a model that is evaluated numerically only
  (``ClosedFormModel.numeric_only``), is the model's own Python at each state, stacked;
  ``per_state`` says which and why, and the report names them;
* a method the model leaves to the interface is formed from the batch of its parts as
  ``ClosedFormModel`` forms it: the bias C q̇ + H (or C·q̇ + H), T = ½ q̇ᵀ M q̇, det M by LU,
  M⁻¹ by solving with M, q̈ = M⁻¹ (B u + W w − D q̇ − bias); the derived inertia scale
  from the bounds of M's terms at all states at once (``DerivedScales.diagonal_at``).

A generated function is compared with the model's own Python at the first state before it
is used: the generated code is SymPy's arrangement of the same formulas, so the two agree
to rounding (a few ε of the entries' size, times the cancellation in them); a difference
above ``AGREEMENT`` of the largest entry means the code does something SymPy did not see
(a test on the type of its argument, a global it reads), and the method is evaluated with
the model's own Python instead, with the reason.

``python_only=True`` evaluates every method the model writes with its own Python: the
high-precision re-judge (``pendverify.checks.precision``) hands a model whose methods run
in mpmath and round to double.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.interface import BiasOnlyModel
from pendverify.analytic.numeric_values import model_value
from pendverify.checks.scaling import mv
from pendverify.numerics.codegen.vectorised import METHODS, generated

#: generated and own code differ by more than this fraction of the largest entry: not the same code
AGREEMENT = 1e-6


class ClosedForms:
    """The closed forms of ``model`` at states Q, V, U, W (rows, batch axis first)."""

    def __init__(self, model, Q, V, U, W, python_only: bool = False):
        self.model, self.n = model, len(Q)
        self.arrays = {"q": Q, "v": V, "u": U, "w": W}
        self.written = set(type(model).own_methods())
        self.python_only = python_only
        self._values: dict[str, np.ndarray] = {}
        self._constants: dict[tuple, object] = {}
        #: {method: why it is evaluated with the model's own Python, state by state}
        self.per_state: dict[str, str] = {}

    # --- what the checks ask for -------------------------------------------------------
    def value(self, name: str) -> np.ndarray:
        """Method ``name`` at every state, as a float array with the batch axis first."""
        if name not in self._values:
            self._values[name] = self._evaluate(name)
        return self._values[name]

    def constant(self, name: str, *args):
        """A method called once: without state (D, B, W, the gravity scale) or at a fixed state."""
        key = (name, *(np.asarray(a).tobytes() for a in args))
        if key not in self._constants:
            self._constants[key] = model_value(self.model, name, *args)
        return self._constants[key]

    def replace(self, values: dict[str, np.ndarray]) -> None:
        """Method ``name``'s values at every state are ``values[name]`` (computed elsewhere)."""
        for name, value in values.items():
            self._values[name] = np.asarray(value, dtype=float)

    def replace_constant(self, name: str, value) -> None:
        """Method ``name`` (called without arguments) is ``value`` (computed elsewhere)."""
        self._constants[(name,)] = value

    # --- how ----------------------------------------------------------------------------
    def _evaluate(self, name: str) -> np.ndarray:
        if name in self.written:
            return self._written(name)
        derived = {
            "bias": self._bias,
            "kinetic_energy": self._kinetic_energy,
            "det_mass_matrix": self._det,
            "inverse_mass_matrix": self._inverse,
            "acceleration": self._acceleration,
        }
        if name in derived:
            return derived[name]()
        if name == "diagonal_scale":  # derived from M's terms, evaluated on all states at once
            return self.model.derived_scales().diagonal_at(self.arrays["q"])
        return self._python(name)

    def _written(self, name: str) -> np.ndarray:
        own = self._call(name, 0)
        if self.model.numeric_only and not self.python_only:
            self.per_state[name] = self.model.numeric_only
        if self.python_only or self.model.numeric_only:
            return self._python(name, first=own)
        module = generated(type(self.model))
        function = module.FUNCTIONS.get(name)
        if function is None:
            self.per_state[name] = module.MISSING.get(name, "not generated")
            return self._python(name, first=own)
        P = [float(getattr(self.model.params, p)) for p in module.PARAMETERS]
        a = self.arrays
        with np.errstate(all="ignore"):
            values = function(P, a["q"], a["v"], a["u"], a["w"]).reshape((self.n, *own.shape))
        size = float(np.max(np.abs(own), initial=0.0))
        if not np.all(np.abs(values[0] - own) <= AGREEMENT * size):
            self.per_state[name] = (
                f"its generated code gives {values[0].ravel().tolist()} where the model's own Python "
                f"gives {own.ravel().tolist()} at the first state"
            )
            return self._python(name, first=own)
        return values

    def _call(self, name: str, i: int) -> np.ndarray:
        """Method ``name`` at state i, through the model boundary (``analytic.numeric_values``)."""
        return model_value(self.model, name, *(self.arrays[a][i] for a in METHODS[name]))

    def _python(self, name: str, first=None) -> np.ndarray:
        """The model's own method at each state (once, broadcast, for a method without arguments)."""
        if first is None:
            first = self._call(name, 0)
        out = np.empty((self.n, *first.shape))
        out[0] = first
        if METHODS[name] == "":
            out[1:] = first
            return out
        for i in range(1, self.n):
            out[i] = self._call(name, i)
        return out

    # --- the interface's derived methods, on stacked arrays (as ``ClosedFormModel`` forms them) ---
    def _bias(self) -> np.ndarray:
        if isinstance(self.model, BiasOnlyModel):
            return self.value("coriolis_force") + self.value("gravity")
        return mv(self.value("coriolis_matrix"), self.arrays["v"]) + self.value("gravity")

    def _kinetic_energy(self) -> np.ndarray:
        V = self.arrays["v"]
        return 0.5 * ((V[:, None, :] @ self.value("mass_matrix")) @ V[:, :, None])[:, 0, 0]

    def _det(self) -> np.ndarray:
        return np.linalg.det(self.value("mass_matrix"))

    def _inverse(self) -> np.ndarray:
        M = self.value("mass_matrix")
        return np.linalg.solve(M, np.broadcast_to(np.eye(M.shape[-1]), M.shape))

    def _acceleration(self) -> np.ndarray:
        a = self.arrays
        force = (
            mv(self.constant("input_matrix"), a["u"])
            + mv(self.constant("disturbance_matrix"), a["w"])
            - mv(self.constant("damping_matrix"), a["v"])
            - self.value("bias")
        )
        return np.linalg.solve(self.value("mass_matrix"), force[..., None])[..., 0]
