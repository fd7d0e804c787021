"""One model, one Pinocchio system and a batch of states: every quantity the checks need, once.

``CheckBatch`` holds the states as arrays (batch axis first; one state is the batch of one)
and computes, each once for all states and all checks: the closed forms
(``forms``: ``pendverify.checks.closed_forms``), Pinocchio's quantities (``pin``:
``pendverify.robot.batch``), the quantities the measures read (``terms``:
``pendverify.checks.quantities``), the largest angle |θ|max of each state, the coordinate
map's amplification c_T and the term amplification A (``lever``:
``pendverify.checks.amplification``).  The trust rule (``pendverify.checks.trust``) and
every check (``pendverify.checks.judge.collect``) read them from here.

``pinocchio_angles`` maps the states' angles to those Pinocchio is evaluated at (the stress
catalogue's 2πk-invariance case reduces them to (−π, π]); A is taken at the states' own
angles.  ``python_only`` evaluates the closed forms with the model's own code state by state
(the high-precision re-judge, ``pendverify.checks.precision``).  No result depends on the
other states of the batch, on its size or on its order: every operation is elementwise over
states or one state's matrix algebra.
"""

from __future__ import annotations

import contextlib
from functools import cached_property

import numpy as np

from pendverify.checks.amplification import term_amplification_batch
from pendverify.checks.closed_forms import ClosedForms
from pendverify.checks.quantities import Terms
from pendverify.checks.sampling import State
from pendverify.robot.batch import PinocchioBatch, configurations


def _rows(states, attribute: str, n: int | None) -> np.ndarray:
    values = np.array([getattr(s, attribute) for s in states], dtype=float)
    return values.reshape(len(states), -1 if n is None else n)


#: the lists of ``recording_batches`` open now: each new batch is appended to every one
_RECORDERS: list[list] = []


@contextlib.contextmanager
def recording_batches():
    """A list of every ``CheckBatch`` made while the block runs (``bench certify`` times their work)."""
    made: list = []
    _RECORDERS.append(made)
    try:
        yield made
    finally:
        _RECORDERS.remove(made)


class CheckBatch:
    """``model`` and ``system`` at ``states``: the quantities of every check, once for all states."""

    def __init__(
        self, model, system, states, pinocchio_angles=None, python_only: bool = False, replaced=None
    ):
        if not states:
            raise ValueError("a batch needs at least one state")
        self.model, self.system, self.states = model, system, list(states)
        self.pinocchio_angles = pinocchio_angles
        self.python_only = python_only
        self.replaced = replaced or {}
        self.Q = _rows(states, "q", model.nv)
        self.V = _rows(states, "v", model.nv)
        self.U = _rows(states, "u", None)
        self.W = _rows(states, "w", None)
        for made in _RECORDERS:
            made.append(self)

    def __len__(self) -> int:
        return len(self.states)

    def subset(self, indices, python_only: bool | None = None) -> CheckBatch:
        """The batch of the states at ``indices`` (same model, system and angle map)."""
        precise = self.python_only if python_only is None else python_only
        states = [self.states[i] for i in indices]
        return CheckBatch(self.model, self.system, states, self.pinocchio_angles, precise)

    @cached_property
    def forms(self) -> ClosedForms:
        forms = ClosedForms(self.model, self.Q, self.V, self.U, self.W, self.python_only)
        if not self.model.has_mass_matrix:
            # q̈ alone: the sizes the tolerances are judged against are the URDF's (its M, |M_ii|, and
            # its gravity bound), not a closed form's (``AccelerationOnlyModel``); an M the model
            # derives from q̈ (``mass_from_acceleration``) is its own, for crba to compare
            M = self.pin.mass_matrix()
            forms.replace({"diagonal_scale": np.abs(np.diagonal(M, axis1=-2, axis2=-1))})
            if not self.model.mass_from_acceleration:
                forms.replace({"mass_matrix": M})
            forms.replace_constant("gravity_scale", urdf_gravity_scale(self.model, self.system))
        forms.replace(self.replaced)
        return forms

    @cached_property
    def pin(self) -> PinocchioBatch:
        angles = self.Q if self.pinocchio_angles is None else self.pinocchio_angles(self.Q)
        return self.system.at(angles, self.V)

    @cached_property
    def terms(self) -> Terms:
        return Terms(self)

    @cached_property
    def c_T(self) -> float:
        """cond₂(T)², the coordinate map's amplification (``CoordinateMap.amplification``)."""
        return self.system.cmap.amplification

    @cached_property
    def angle(self) -> np.ndarray:
        """|θ|max over the angular coordinates of each state (0 for a model without angles)."""
        return np.max(np.abs(self.Q[:, np.array(self.model.angular)]), axis=1, initial=0.0)

    @cached_property
    def lever(self) -> np.ndarray:
        """A at each state (``checks.amplification``), at the states' own angles."""
        if self.pinocchio_angles is None:
            own = self.pin
        else:
            own = PinocchioBatch(self.system, self.Q, self.V)
        diag = np.diagonal(own.crba_upper(), axis1=-2, axis2=-1)
        S = self.forms.value("diagonal_scale")
        return term_amplification_batch(self.system, configurations(self.system.cmap, self.Q), diag, S)


#: the grid points per angle on which ``urdf_gravity_scale`` takes the largest |H_i|
GRAVITY_GRID = 8


def urdf_gravity_scale(model, system) -> np.ndarray:
    """max |H_i(q)| of the URDF over a grid of configurations: the gravity scale of a model without H.

    Angles on GRAVITY_GRID points over [−π, π) each (positions at zero: gravity of a prismatic
    joint's subtree does not depend on its position); H_i is a sum of sinusoids of the angles, so
    the grid's largest value is at least cos(π/GRAVITY_GRID) ≈ 0.92 of the largest over all q for
    one sinusoid: the size of the gravity terms, as the Σ|terms| of a closed form's H is.
    """
    angular = np.array(model.angular)
    points = np.linspace(-np.pi, np.pi, GRAVITY_GRID, endpoint=False)
    k = int(np.count_nonzero(angular))
    if k == 0:  # no angle: gravity does not change with a position, one configuration tells
        grid = np.zeros((1, 0))
    elif k > 4:  # a grid too large: the same number of seeded random configurations instead
        grid = np.random.default_rng(0).uniform(-np.pi, np.pi, (GRAVITY_GRID**4, k))
    else:
        grid = np.stack(np.meshgrid(*[points] * k, indexing="ij"), axis=-1).reshape(-1, k)
    Q = np.zeros((len(grid), model.nv))
    Q[:, angular] = grid
    H = system.at(Q, np.zeros_like(Q)).gravity()
    return np.max(np.abs(H), axis=0)


def state_at(model, q, v=None) -> State:
    """The state at configuration q (and rate v; zero rates, inputs and disturbances otherwise)."""
    q = np.asarray(q, dtype=float)
    v = np.zeros(model.nv) if v is None else np.asarray(v, dtype=float)
    return State("q", q, v, np.zeros(len(model.inputs)), np.zeros(len(model.disturbances)))


def world_lever(model, system, q) -> float:
    """A ≥ 1 at configuration q: how much larger Pinocchio's world-frame terms are than M's diagonal.

    Pinocchio expresses spatial inertias about the world origin, so a joint whose subtree
    sits far from it (a cart 10 m along the rail, a small link 2 at the end of a long link 1)
    carries second moments m·|c|² ≫ M_ii into its recursions, which cancel in the result:
    its rounding is ε·A times the result's scale (``pendverify.checks.amplification``).
    """
    return float(CheckBatch(model, system, [state_at(model, q)]).lever[0])
