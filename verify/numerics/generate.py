"""Every numeric back end generated from the model: the model is the one source.

What is generated.  For a model class with n coordinates, ``pendverify.analytic.symbolic_reading``
reads its closed forms as SymPy expressions (the model's own code, called with
symbols for q, q̇ and the parameters): M(q) from ``mass_matrix``, the bias
C(q, q̇)·q̇ + H(q) from ``bias`` (the interface's ``coriolis_matrix @ v + gravity``,
or ``coriolis_force + gravity`` for a ``BiasOnlyModel``) and V(q) from
``potential_energy`` (``codegen.expressions``).  From them ``pendverify.numerics.codegen``
writes one Python module per model:

* numba functions with n literal (``codegen.compiled``): ``_rhs_t(P, t, x, out)`` (ẋ at
  time t under τ = B (u0 − K x) − D q̇ + f(t), M q̈ = τ − bias solved by an unrolled
  root-free Cholesky M = L diag(d) Lᵀ, with the work integrals dW_in/dt = q̇ᵀ (B u + f(t)),
  dW_diss/dt = q̇ᵀ D q̇ when x has 2n + 2 entries) and ``_rhs(P, x, out)``, the same at
  t = 0; ``_hamilton(P, y, out)`` (q̇ and ṗ in canonical
  coordinates, derivation there) and ``_to_momentum``; common subexpressions
  eliminated (``sympy.cse``), floats as exact literals;
* the DOP853 stepper of ``pendverify.numerics.integrators.dop853`` and the fixed-step methods of
  ``pendverify.numerics.integrators.fixedstep``, copied from their templates so that they call this
  model's functions directly (``codegen.templates``, which says why copied; inlined where short,
  ``codegen.compiled``);
* plain-Python ``field``, ``energy`` and ``potential`` generic over the number type
  (float, numpy, mpmath, Decimal, Taylor series) for the high-precision references
  (``codegen.generic``).

The module is cached on disk by the digest of its source, and a signed index maps the
model's source files (and pendverify's version) to it, so a second process neither runs
SymPy nor compiles (``codegen.cache``; what is verified before anything is imported:
``docs/code-cache.md``).

Packed layout (``GeneratedSystem.packed``), for n coordinates, n_p parameters and
nu inputs of the force law::

    P[0] = n,  P[1] = nu,
    P[2 : 2 + n_p]            the parameter values, in the field order of the model's params_type,
    then D (n × n), B (n × nu), K (nu × 2n), u0 (nu), matrices row-major;
    then, only when the system has forcing: the number of channels, and per channel
    g (n), its amplitude a, its number of components m and m pairs (ω_k, φ_k).

The force law τ = B (u0 − K x) − D q̇ covers every time-invariant scene: conservative
(K = 0, D = 0), joint friction (any D: a plug-in's absolute angles couple it), PD control (B = I, K = [kp kd],
u0 = kp·target), LQR about upright (B = e_q, K the gain), a constant input (K = 0).  The
forcing f(t) = Σ_channels g·a·Σ_k sin(ω_k t + φ_k) adds the smooth time-varying laws
(``Forcing``): a sine input u = offset + A sin(2π f t + φ) (the offset in u0, one channel
per input, g the column of B) and band-limited noise w (one channel per disturbance, g the
column of W, its seeded components).  Laws that jump or kink (step, table, impulse) and a
saturated LQR are not compiled (``FastPathError``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from pendverify.errors import FastPathError, PendverifyError
from pendverify.numerics.codegen.cache import GeneratedKernel, kernel
from pendverify.numerics.forcing import NO_FORCING, Forcing, forcing_of

HEADER = 2  # P[0] = n, P[1] = nu
#: V_min search: grid points over the angles (a full grid up to this many, else random)
MINIMUM_SAMPLES = 1 << 16
MINIMUM_REFINED = 8  # best grid points refined by BFGS


def _float_sincos(u):
    return np.sin(u), np.cos(u)


@dataclass(frozen=True)
class GeneratedSystem:
    """A model's generated module and its force law τ = B (u0 − K x) − D q̇ + f(t), packed."""

    kernel: GeneratedKernel
    params: np.ndarray  # parameter values in the field order of the model's params_type
    D: np.ndarray  # (n, n) viscous friction
    B: np.ndarray  # (n, nu) input map
    K: np.ndarray  # (nu, 2n) state feedback
    u0: np.ndarray  # (nu,) feed-forward input
    anchors: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros((0, 0)))  # special states' q
    forcing: Forcing = NO_FORCING  # time-varying generalized forces f(t)

    @property
    def model(self) -> str:
        return self.kernel.module.MODEL

    @property
    def module(self):
        return self.kernel.module

    @property
    def nv(self) -> int:
        return self.D.shape[0]

    @property
    def conservative(self) -> bool:
        return not (np.any(self.D) or np.any(self.K) or np.any(self.u0) or self.forcing)

    def packed(self) -> np.ndarray:
        """The one array the generated functions take (layout in the module docstring)."""
        head = np.array([self.nv, self.B.shape[1]], dtype=float)
        matrices = [self.D.ravel(), self.B.ravel(), self.K.ravel(), self.u0]
        return np.concatenate([head, self.params, *matrices, self.forcing.packed()])

    @classmethod
    def from_model(
        cls, model, D=None, B=None, K=None, u0=None, fresh: bool = False, forcing: Forcing = NO_FORCING
    ) -> GeneratedSystem:
        """Pack a ``ClosedFormModel`` instance with its parameter values; no forces unless given.

        ``D``: the friction matrix, or its diagonal as a vector; ``forcing``: f(t)."""
        k = kernel(type(model), fresh=fresh)
        n = model.nv
        names = tuple(f.name for f in dataclasses.fields(model.params_type))
        if k.n != n or k.parameters != names:
            raise PendverifyError(f"{model.name}: the generated kernel {k.path} does not match the model")
        params = np.array([float(getattr(model.params, f)) for f in names])
        B = np.zeros((n, 0)) if B is None else np.asarray(B, float).reshape(n, -1)
        nu = B.shape[1]
        K = np.zeros((nu, 2 * n)) if K is None else np.asarray(K, float).reshape(nu, 2 * n)
        u0 = np.zeros(nu) if u0 is None else np.asarray(u0, float).reshape(nu)
        D = np.zeros((n, n)) if D is None else np.asarray(D, float)
        D = np.ascontiguousarray(np.diag(D) if D.ndim == 1 else D.reshape(n, n))
        anchors = np.array([np.asarray(q, float).reshape(n) for q in model.special_states().values()])
        B, K = np.ascontiguousarray(B), np.ascontiguousarray(K)
        return cls(k, params, D, B, K, u0, anchors.reshape(-1, n), forcing)

    @classmethod
    def from_dynamics(cls, dyn, source: str = "<fast path>") -> GeneratedSystem:
        """The force law of a built scene (``simulation.dynamics.Dynamics``), or a FastPathError."""
        n = dyn.nv
        sine_u0, forcing = forcing_of(dyn, source)
        D = dyn.D
        B = K = u0 = None
        law = dyn.u_of
        if law is not None:
            B = dyn.model.input_matrix()
            if law.kind == "sine":
                u0 = sine_u0
            elif law.kind == "constant":
                u0 = law.value
            elif law.kind == "pd":
                K = np.hstack([np.diag(law.kp), np.diag(law.kd)])
                u0 = law.kp * law.target
            elif law.kind == "lqr" and law.saturation is None:
                K, u0 = law.K, np.zeros(B.shape[1])
            else:
                raise FastPathError(
                    source,
                    "effects.actuation",
                    law.kind,
                    "compiled laws are constant, sine, pd and lqr without saturation",
                )
            K = np.zeros((B.shape[1], 2 * n)) if K is None else K
        return cls.from_model(dyn.model, D, B, K, u0, forcing=forcing)

    # --- evaluations -----------------------------------------------------------------
    def rhs(self, x: np.ndarray, t: float | None = None) -> np.ndarray:
        """ẋ at x: at time t (``_rhs_t``), or the autonomous ``_rhs`` (t = 0) without one."""
        out = np.empty_like(x, dtype=float)
        x = np.ascontiguousarray(x, dtype=float)
        if t is None:
            self.kernel.rhs(self.packed(), x, out)
        else:
            self.module._rhs_t(self.packed(), float(t), x, out)
        return out

    def scipy_rhs(self):
        """fun(t, x) for ``solve_ivp`` calling the compiled right-hand side."""
        P, rhs = self.packed(), self.module._rhs_t

        def fun(t, x):
            out = np.empty(x.shape[0])
            rhs(P, float(t), x, out)
            return out

        return fun

    def float_numbers(self) -> dict:
        """The system's numbers as the generic functions take them, in floats."""
        return {
            "params": [float(v) for v in self.params],
            "D": self.D.tolist(),
            "B": self.B.tolist(),
            "K": self.K.tolist(),
            "u0": self.u0.tolist(),
        }

    def potential(self, Q: np.ndarray) -> np.ndarray:
        """V at each row of Q (float), from the generated ``potential``."""
        error = self.module.ENERGY_ERROR
        if error:
            raise PendverifyError(f"{self.model}: {error}")
        Q = np.atleast_2d(np.asarray(Q, float))
        value = self.module.potential(self.float_numbers(), list(Q.T), float, _float_sincos)
        return np.broadcast_to(np.asarray(value, float), Q.shape[:1]).copy()

    @functools.cached_property
    def potential_minimum(self) -> float:
        """min V over the angle coordinates: the scale E(x0) − V_min of relative energy errors.

        V of the model's angles is a bounded, 2π-periodic function (positions, which V
        need not bound, stay where the special states put them, zero by default):
        every angle is sampled on a grid of ``MINIMUM_SAMPLES`` points in all (random
        points beyond four angles), with the special states added, and the
        ``MINIMUM_REFINED`` lowest are refined by BFGS over the angles.  On a smooth
        minimum V's error is quadratic in the position error, so the value is good to
        rounding; a global minimum missed between grid points could only enlarge the
        scale, and the scale only normalises the energy error (no check depends on more).
        The reference systems' minimum is known in closed form; the tests compare.
        """
        from scipy.optimize import minimize

        n, angles = self.nv, np.array(self.module.ANGULAR, bool)
        bases = self.anchors if len(self.anchors) else np.zeros((1, n))
        na = int(angles.sum())
        if na == 0:
            return float(np.min(self.potential(bases)))
        per = int(MINIMUM_SAMPLES ** (1 / na))
        if na <= 4 and per >= 8:
            axes = np.meshgrid(*[np.linspace(-math.pi, math.pi, per, endpoint=False)] * na, indexing="ij")
            grid = np.stack([a.ravel() for a in axes], axis=1)
        else:
            grid = np.random.default_rng(0).uniform(-math.pi, math.pi, (MINIMUM_SAMPLES, na))
        candidates = []
        for base in bases:
            Q = np.tile(base, (grid.shape[0] + 1, 1))
            Q[1:, angles] = grid
            candidates.append(np.column_stack([self.potential(Q), Q]))
        table = np.vstack(candidates)
        best = table[np.argsort(table[:, 0])[:MINIMUM_REFINED]]
        values = [float(table[:, 0].min())]
        for row in best:
            q = row[1:].copy()

            def v(a, q=q):
                q[angles] = a
                return float(self.potential(q)[0])

            res = minimize(v, row[1:][angles], method="BFGS")
            if np.isfinite(res.fun):
                values.append(float(res.fun))
        return min(values)


def distinct_modules(systems) -> list[GeneratedSystem]:
    """The first of ``systems`` for each generated module (compilation is per module)."""
    seen = {}
    for system in systems:
        seen.setdefault(id(system.module), system)
    return list(seen.values())
