"""The checks evaluated over all states at once: the default path of ``run_check`` and ``run_checks``.

``BatchContext`` holds one model, one system and its states as arrays (batch axis
first), and computes each quantity once for all states and all checks: the closed
forms by ``pendverify.checks.forms_batch``, Pinocchio by ``pendverify.robot.batch``, the
term amplification A by ``pendverify.checks.amplification``.  ``collect_batch`` runs a
check's measure (``pendverify.checks.quantities``: the same code the per-state path runs)
on the batch's terms and forms its tolerances as arrays, K·ε·((1 + |θ|max)·c_T + (A − 1))
+ a/s per state — the argument for them is in ``pendverify.checks.catalogue``; the
verdict is ``pendverify.checks.judge.conclude``, shared with the per-state path.

The numbers are the per-state path's, bit for bit (``tests/checks/test_batch_checks.py``
compares the two on every check).  Whatever the batch cannot do exactly as the per-state
path does — a system wrapper without a batch, an error state, an exception anywhere,
NumPy set to raise on floating-point errors — falls back to ``run_check_per_state`` for
that check, which then refuses, notes or raises exactly as it always has.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from pendverify.checks.amplification import term_amplification_batch
from pendverify.checks.forms_batch import ClosedFormBatch
from pendverify.checks.judge import Evidence, rounding_tolerance
from pendverify.checks.quantities import MEASURES, Terms
from pendverify.checks.trust import REFUSE_REL
from pendverify.robot.batch import PinocchioBatch, batch_source, configurations


class BatchContext:
    """One model, one system, its states: every quantity the checks need, once for all states."""

    def __init__(self, model, system, states):
        self.model, self.system, self.states = model, system, states
        self.source = batch_source(system)
        self.Q = np.array([s.q for s in states], dtype=float).reshape(len(states), model.nv)
        self.V = np.array([s.v for s in states], dtype=float).reshape(len(states), model.nv)
        self.U = np.array([s.u for s in states], dtype=float).reshape(len(states), -1)
        self.W = np.array([s.w for s in states], dtype=float).reshape(len(states), -1)
        #: (check, why) for each check that fell back to the per-state path
        self.fallbacks: list[tuple[str, str]] = []

    @classmethod
    def of(cls, model, system, states) -> BatchContext | None:
        """The batch of ``states``, or None where only the per-state path applies."""
        errors = np.geterr()
        if len(states) < 2 or batch_source(system) is None:
            return None
        if any(errors[k] in ("raise", "call") for k in ("over", "divide", "invalid", "under")):
            return None
        try:
            return cls(model, system, states)
        except (ValueError, TypeError):
            return None

    @cached_property
    def forms(self) -> ClosedFormBatch:
        return ClosedFormBatch(self.model, self.states, self.Q, self.V, self.U, self.W)

    @cached_property
    def pin(self) -> PinocchioBatch:
        return PinocchioBatch(self.system, self.Q, self.V)

    @cached_property
    def c_T(self) -> float:
        """cond₂(T)², the coordinate map's amplification (``CoordinateMap.amplification``)."""
        return self.system.cmap.amplification

    @cached_property
    def angle(self) -> np.ndarray:
        return np.max(np.abs(self.Q[:, np.array(self.model.angular)]), axis=1, initial=0.0)

    @cached_property
    def lever(self) -> np.ndarray:
        """A at each state (``scaling.world_lever``), at the states' own angles."""
        base, angles = self.source
        if angles is None:
            configs, upper = self.pin.q, self.pin.crba_upper()
        else:
            import pinocchio as pin

            configs = configurations(base.cmap, self.Q)
            upper = np.array([pin.crba(base.model, base.data, q) for q in configs])
        diag = np.diagonal(upper, axis1=-2, axis2=-1)
        return term_amplification_batch(self.model, base, configs, diag, self.forms.value("diagonal_scale"))

    @cached_property
    def terms(self) -> BatchTerms:
        return BatchTerms(self)


class BatchTerms(Terms):
    """The batch's terms for the measures: stacked arrays, batch axis first."""

    def __init__(self, ctx: BatchContext):
        self.ctx = ctx
        self.q, self.v, self.u, self.w_in = ctx.Q, ctx.V, ctx.U, ctx.W
        self.angular, self.coordinates = ctx.model.angular, ctx.model.coordinates

    def __getattr__(self, name):
        if name.startswith("__") or name not in _BATCH_QUANTITIES:
            raise AttributeError(name)
        value = _BATCH_QUANTITIES[name](self.ctx)
        self.__dict__[name] = value
        return value

    def acceleration_pin(self, tau):
        return self.ctx.pin.acceleration(tau)


def _zero(ctx):
    return np.zeros(ctx.model.nv)


_BATCH_QUANTITIES = {
    "S": lambda c: c.forms.value("diagonal_scale"),
    "g_scale": lambda c: c.forms.constant("gravity_scale"),
    "D": lambda c: c.forms.constant("damping_matrix"),
    "B": lambda c: c.forms.constant("input_matrix"),
    "W": lambda c: c.forms.constant("disturbance_matrix"),
    "allowance": lambda c: c.system.allowance,
    "D_urdf": lambda c: c.system.cmap.matrix_to_model(np.diag(c.system.urdf_damping())),
    "M_pin": lambda c: c.pin.mass_matrix(),
    "M_hand": lambda c: c.forms.value("mass_matrix"),
    "bias_pin": lambda c: c.pin.bias(),
    "bias_hand": lambda c: c.forms.value("bias"),
    "H_pin": lambda c: c.pin.gravity(),
    "H_hand": lambda c: c.forms.value("gravity"),
    "C_pin": lambda c: c.pin.coriolis_matrix(),
    "C_hand": lambda c: c.forms.value("coriolis_matrix"),
    "Mdot_pin": lambda c: c.pin.mass_matrix_derivative(),
    "det_hand": lambda c: c.forms.value("det_mass_matrix"),
    "det_pin": lambda c: c.pin.det_mass_matrix(),
    "Minv_pin": lambda c: c.pin.inverse_mass_matrix(),
    "Minv_hand": lambda c: c.forms.value("inverse_mass_matrix"),
    "a_hand": lambda c: c.forms.value("acceleration"),
    "KE_pin": lambda c: c.pin.kinetic_energy(),
    "KE_hand": lambda c: c.forms.value("kinetic_energy"),
    "V_pin": lambda c: c.pin.potential_energy(),
    "V_pin0": lambda c: c.system.potential_energy(_zero(c)),
    "V_hand": lambda c: c.forms.value("potential_energy"),
    "V_hand0": lambda c: c.forms.constant("potential_energy", _zero(c)),
}


def collect_batch(check, ctx: BatchContext) -> Evidence:
    """The check at every state at once: the ``Evidence`` the per-state path would collect."""
    lever = ctx.lever if check.world_frame else 1.0
    rounding = np.broadcast_to(rounding_tolerance(check, ctx.angle, ctx.c_T, lever), ctx.angle.shape)
    judged = np.flatnonzero(rounding <= REFUSE_REL)
    refused = [(int(i), float(rounding[i])) for i in np.flatnonzero(~(rounding <= REFUSE_REL))]
    m = MEASURES[check.name](ctx.terms)
    n = len(ctx.states)
    error, scale, allowance = (
        np.broadcast_to(np.asarray(x, dtype=float), (n,)) for x in (m.error, m.scale, m.allowance)
    )
    error, scale, allowance, r = error[judged], scale[judged], allowance[judged], rounding[judged]
    with np.errstate(all="ignore"):  # as ``judge.judge_state``, state by state
        positive = scale > 0
        rel_tol = np.where(positive, r + allowance / scale, r)
        rel_err = np.where(positive, error / scale, np.where(error == 0, 0.0, np.inf))
    noted = np.broadcast_to(np.asarray(m.noted, dtype=bool), (n,))[judged]
    nan = np.isnan(rel_err)
    notes = []
    for k in np.flatnonzero(noted | nan)[:3]:
        i = int(judged[k])
        note = m.describe(i) if noted[k] else "NaN"
        notes.append(f"{ctx.states[i].label}: {note}")
    return Evidence(judged, r.copy(), np.where(nan, np.inf, rel_err), rel_tol, error.copy(), refused, notes)
