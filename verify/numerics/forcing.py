"""Time-varying generalized forces the compiled right-hand side carries: f(t) as sums of sinusoids.

The smooth time-varying laws of a scene (``pendverify.simulation.laws``) are sums of
sinusoids: a sine input u = offset + A sin(2π f t + φ) and band-limited noise
w = a Σ_k sin(2π f_k t + φ_k) (seeded f_k, φ_k, a = std·√(2/N)).  Through the input map B
and the disturbance map W they make

    f(t) = Σ_channels g · a · Σ_k sin(ω_k t + φ_k),

one channel per input (g the column of B, the offset going to u0 instead) and one per
disturbance (g the column of W).  ``Forcing`` holds the channels and packs them after u0
(layout in ``pendverify.numerics.generate``); the generated ``_rhs_t`` adds f(t) to the
input force, so the work integral W_in = ∫ q̇ᵀ (B u + W w) dt includes it.  ω = 2π·f is
computed as the laws compute it, so each sine's argument is the same double; the sums
run in another order (rounding-level differences).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.errors import FastPathError


@dataclass(frozen=True)
class Forcing:
    """Time-varying generalized forces f(t) = Σ_c g_c·a_c·Σ_k sin(ω_ck t + φ_ck), one entry per channel."""

    g: tuple = ()  # per channel: the column it acts through (n)
    amplitude: tuple = ()  # per channel: a
    omega: tuple = ()  # per channel: the angular frequencies ω_k (rad/s)
    phase: tuple = ()  # per channel: the phases φ_k (rad)

    def __bool__(self) -> bool:
        return bool(self.g)

    def add(self, g, amplitude: float, omega, phase) -> Forcing:
        omega, phase = np.atleast_1d(np.asarray(omega, float)), np.atleast_1d(np.asarray(phase, float))
        return Forcing(
            (*self.g, tuple(float(x) for x in np.ravel(g))),
            (*self.amplitude, float(amplitude)),
            (*self.omega, tuple(omega.tolist())),
            (*self.phase, tuple(phase.tolist())),
        )

    def packed(self) -> np.ndarray:
        """[channels, then per channel g, a, m, ω_1, φ_1, …], or nothing without forcing."""
        if not self:
            return np.zeros(0)
        parts = [[float(len(self.g))]]
        for g, a, omega, phase in zip(self.g, self.amplitude, self.omega, self.phase, strict=True):
            pairs = np.column_stack([omega, phase]).ravel()
            parts.append([*g, a, float(len(omega)), *pairs])
        return np.concatenate([np.asarray(p, float) for p in parts])

    def at(self, t: float) -> np.ndarray:
        """f(t), in NumPy (the compiled code sums in its own order: equal to rounding)."""
        total = 0.0
        for g, a, omega, phase in zip(self.g, self.amplitude, self.omega, self.phase, strict=True):
            total = total + np.asarray(g) * (a * np.sum(np.sin(np.asarray(omega) * t + np.asarray(phase))))
        return np.asarray(total, float)


NO_FORCING = Forcing()


def forcing_of(dyn, source: str) -> tuple[np.ndarray | None, Forcing]:
    """(u0 or None, forcing) of a scene's time-varying laws, or a FastPathError naming the key."""
    forcing, u0 = NO_FORCING, None
    law, model = dyn.u_of, dyn.model
    if law is not None and law.kind == "sine":
        B = np.asarray(model.input_matrix(), float).reshape(model.nv, -1)
        u0 = np.asarray(law.offset, float)
        omega = 2 * np.pi * law.frequency  # as the law computes 2π·f·t + φ
        for j in range(B.shape[1]):
            forcing = forcing.add(B[:, j], law.amplitude[j], omega, law.phase)
    noise = dyn.w_of
    if noise is not None:
        if noise.kind != "noise":
            why = "not compiled: time-varying with jumps (compiled disturbance: noise)"
            raise FastPathError(source, "effects.disturbance", noise.kind, why)
        W = np.asarray(model.disturbance_matrix(), float).reshape(model.nv, -1)
        a = noise.std * np.sqrt(2.0 / noise.components)  # as ``laws.Noise``
        for c in range(W.shape[1]):
            forcing = forcing.add(W[:, c], a[c], 2 * np.pi * noise.frequencies[c], noise.phases[c])
    return u0, forcing
