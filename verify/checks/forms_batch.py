"""A model's closed forms at every state of a batch, each method evaluated once for all states.

How, per method (``ClosedFormBatch.value``):

1. a hand-written method whose code is elementwise (``checks.elementwise``) runs once on
   ``Lanes`` (``pendverify.checks.lanes``): the model's own code, its own arithmetic, its
   ``@`` and ``np.linalg`` as one state's BLAS/LAPACK calls (``checks.lane_arrays``);
2. the interface's derived ``bias``, ``kinetic_energy``, ``inverse_mass_matrix`` and
   ``acceleration`` are formed from the batch of their parts with the same NumPy calls
   on stacked arrays (BLAS and LAPACK are called once per state with the same arguments);
3. anything else — a reduction (``np.sum``, ``.dot``), the SymPy-derived scales, a method
   that raises on ``Lanes`` — is called state by state, as the reference path calls it.

Whatever ran on the batch is compared bit for bit with state-by-state calls at a few
probe states, and a method that differs there is evaluated state by state everywhere;
states whose lanes are ``unsure`` are evaluated one by one.  So the numbers are the
reference path's numbers; ``tests/checks/test_batch_checks.py`` compares the two on every check.

Measured (2010 states, every method the checks call, one core): 11 ms on the batch for
either seed against 150–165 ms calling each method once per state.  Why not the
SymPy-generated back ends (``pendverify.numerics.generate``)?  They would be faster still,
but they are SymPy's rearrangement of the formulas, not the model's code: their
rounding differs from what the reference path (and a user calling the model) computes,
they give M, C·q̇ + H and V but not the hand-written C, det M, M⁻¹ or q̈ the checks
judge, and a model SymPy cannot read would have no batch at all.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel
from pendverify.checks.elementwise import elementwise
from pendverify.checks.lane_arrays import lane_array, lane_twin_class
from pendverify.checks.lanes import lane_math, stack, to_lanes
from pendverify.checks.scaling import mv

#: the arguments of each method the checks call, from the state (q, q̇, u, w)
ARGUMENTS = {
    "mass_matrix": "q",
    "coriolis_matrix": "qv",
    "coriolis_force": "qv",
    "gravity": "q",
    "potential_energy": "q",
    "det_mass_matrix": "q",
    "inverse_mass_matrix": "q",
    "acceleration": "qvuw",
    "diagonal_scale": "q",
    "bias": "qv",
    "kinetic_energy": "qv",
}
#: the derived scales, read by SymPy (their code lies outside the model class): state by state
NEVER_LANES = ("diagonal_scale", "gravity_scale")
PROBES = 4  # states at which a batch evaluation is compared with the state-by-state one


def _interface_default(model, name: str) -> bool:
    owner = next((k for k in type(model).__mro__ if name in vars(k)), None)
    return owner in (ClosedFormModel, BiasOnlyModel)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.ascontiguousarray(a).tobytes() == np.ascontiguousarray(b).tobytes()


class ClosedFormBatch:
    """The model's closed forms at ``states`` (their arrays Q, V, U, W stacked, batch axis first)."""

    def __init__(self, model, states, Q, V, U, W):
        self.model, self.states, self.n = model, states, len(states)
        self.arrays = {"q": Q, "v": V, "u": U, "w": W}
        self._values: dict[str, np.ndarray] = {}
        self._constants: dict[str, object] = {}
        self._twin = None
        #: how each method was evaluated: "lanes", "stacked" or "per state"
        self.how: dict[str, str] = {}

    # --- what the checks ask for ------------------------------------------------------
    def value(self, name: str) -> np.ndarray:
        """Method ``name`` at every state, as a float array with the batch axis first."""
        if name not in self._values:
            self._values[name] = self._evaluate(name)
        return self._values[name]

    def constant(self, name: str, *args):
        """A method without state (D, B, W, the gravity scale) or at a fixed state: called once."""
        key = (name, *(np.asarray(a).tobytes() for a in args))
        if key not in self._constants:
            self._constants[key] = getattr(self.model, name)(*args)
        return self._constants[key]

    # --- how ----------------------------------------------------------------------------
    def _evaluate(self, name: str) -> np.ndarray:
        if self.n <= PROBES or name in vars(self.model) or name not in ARGUMENTS:
            return self._per_state(name)
        default = _interface_default(self.model, name)
        attempt = None
        if default and hasattr(self, f"_stacked_{name}"):
            attempt, how = getattr(self, f"_stacked_{name}"), "stacked"
        elif not (default and name in NEVER_LANES) and elementwise(type(self.model), name):
            attempt, how = (lambda: self._lanes(name)), "lanes"
        if attempt is None:
            return self._per_state(name)
        try:
            values, unsure = attempt()
        except Exception:  # whatever the batch cannot do is done state by state
            return self._per_state(name)
        for i in np.unique(np.linspace(0, self.n - 1, PROBES).astype(int)):
            if (unsure is None or not unsure[i]) and not _same_bits(values[i], self._one(name, i)):
                return self._per_state(name)
        if unsure is not None:
            for i in np.flatnonzero(unsure):
                values[i] = self._one(name, i)
        self.how[name] = how
        return values

    def _one(self, name: str, i: int) -> np.ndarray:
        s = self.states[i]
        state = {"q": s.q, "v": s.v, "u": s.u, "w": s.w}
        return np.asarray(getattr(self.model, name)(*(state[a] for a in ARGUMENTS[name])), dtype=float)

    def _per_state(self, name: str) -> np.ndarray:
        self.how[name] = "per state"
        return np.array([self._one(name, i) for i in range(self.n)], dtype=float)

    def _lanes(self, name: str):
        if self._twin is None:  # made for each batch: a method patched meanwhile is the one called
            twin = object.__new__(lane_twin_class(type(self.model)))
            twin.__dict__.update(self.model.__dict__)
            twin.math = lane_math(self.model.math)
            self._twin = twin
        args = [lane_array(to_lanes(self.arrays[a])) for a in ARGUMENTS[name]]
        with np.errstate(all="ignore"):
            return stack(getattr(self._twin, name)(*args), self.n)

    # --- the interface's derived methods, on stacked arrays (as ``ClosedFormModel`` forms them) ---
    def _stacked_bias(self):
        if isinstance(self.model, BiasOnlyModel):
            return self.value("coriolis_force") + self.value("gravity"), None
        return mv(self.value("coriolis_matrix"), self.arrays["v"]) + self.value("gravity"), None

    def _stacked_kinetic_energy(self):
        V = self.arrays["v"]
        return 0.5 * ((V[:, None, :] @ self.value("mass_matrix")) @ V[:, :, None])[:, 0, 0], None

    def _stacked_inverse_mass_matrix(self):
        M = self.value("mass_matrix")
        return np.linalg.solve(M, np.broadcast_to(np.eye(self.model.nv), M.shape)), None

    def _stacked_acceleration(self):
        a = self.arrays
        force = (
            mv(self.constant("input_matrix"), a["u"])
            + mv(self.constant("disturbance_matrix"), a["w"])
            - mv(self.constant("damping_matrix"), a["v"])
            - self.value("bias")
        )
        return np.linalg.solve(self.value("mass_matrix"), force[..., None])[..., 0], None
