"""The laws u(t, q, q̇) and w(t) a scene's effects evaluate during a simulation.

* ``Constant``: u = value.  ``Step``: ``before`` until ``time``, ``after`` from it.
* ``Sine``: u = offset + amplitude·sin(2π·frequency·t + phase).
* ``TabulatedLaw``: piecewise linear through (times, values), held at the ends.
* ``Pulse``: a rectangular pulse of height impulse/width on [time, time + width), so
  its integral is the impulse.
* ``Noise``: band-limited noise Σ_k a·sin(2π f_k t + φ_k) over ``components`` N
  sinusoids with seeded frequencies f_k in (0, bandwidth] and phases φ_k; each has
  variance a²/2, so a = std·√(2/N) gives the standard deviation ``std``.  Smooth, so
  the integrator needs no breakpoints.
* ``PD``: u = B⁻¹ (kp (target − q) − kd q̇), a joint-space PD force through the
  inverse input map.
* ``LQR``: u = −K (x − x*) about x* = (q*, 0), clipped to ±saturation when given; K is
  set by the simulator from the linearisation (``pendverify.simulation.lqr``).

Every law lists its breakpoints (times where it jumps or kinks) so that the
integrator can stop there rather than step over a discontinuity.  The scene keys
that build them are read by ``pendverify.simulation.effects``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Law:
    """u(t, q, q̇) or w(t): ``kind`` names the type; ``feedback`` laws read the state."""

    kind: str
    size: int
    spec: dict = field(default_factory=dict)
    feedback: bool = False

    def breakpoints(self) -> list[float]:
        return []

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def describe(self) -> str:
        return self.kind


@dataclass
class Constant(Law):
    value: np.ndarray = None

    def __call__(self, t, q, v):
        return self.value


@dataclass
class Step(Law):
    time: float = 0.0
    before: np.ndarray = None
    after: np.ndarray = None

    def breakpoints(self):
        return [self.time]

    def __call__(self, t, q, v):
        return self.after if t >= self.time else self.before


@dataclass
class Sine(Law):
    amplitude: np.ndarray = None
    frequency: float = 1.0
    phase: float = 0.0
    offset: np.ndarray = None

    def __call__(self, t, q, v):
        return self.offset + self.amplitude * np.sin(2 * np.pi * self.frequency * t + self.phase)


@dataclass
class TabulatedLaw(Law):
    times: np.ndarray = None
    values: np.ndarray = None

    def breakpoints(self):
        return list(self.times)

    def __call__(self, t, q, v):
        return np.array([np.interp(t, self.times, col) for col in self.values.T])


@dataclass
class Pulse(Law):
    time: float = 0.0
    width: float = 0.01
    impulse: np.ndarray = None

    def breakpoints(self):
        return [self.time, self.time + self.width]

    def __call__(self, t, q, v):
        inside = self.time <= t < self.time + self.width
        return self.impulse / self.width if inside else np.zeros(self.size)


@dataclass
class Noise(Law):
    """Band-limited noise: per channel, ``components`` sines of seeded frequencies in
    (0, bandwidth] Hz (``frequencies``) and phases (``phases``)."""

    std: np.ndarray = None
    bandwidth: float = 1.0
    seed: int = 0
    components: int = 32
    frequencies: np.ndarray = None
    phases: np.ndarray = None

    def __post_init__(self):
        rng = np.random.default_rng(self.seed)
        self.frequencies = rng.uniform(0.0, self.bandwidth, (self.size, self.components))
        self.frequencies = np.where(self.frequencies == 0.0, self.bandwidth, self.frequencies)
        self.phases = rng.uniform(0.0, 2 * np.pi, (self.size, self.components))

    def __call__(self, t, q, v):
        # each component has variance a²/2; N of them give std² when a = std·√(2/N)
        a = self.std * np.sqrt(2.0 / self.components)
        return a * np.sum(np.sin(2 * np.pi * self.frequencies * t + self.phases), axis=1)


@dataclass
class PD(Law):
    """u = B⁻¹ (kp (target − q) − kd q̇): a joint-space PD force through the inverse input map."""

    kp: np.ndarray = None
    kd: np.ndarray = None
    target: np.ndarray = None
    B_inv: np.ndarray = None

    def __post_init__(self):
        self.feedback = True

    def __call__(self, t, q, v):
        return self.B_inv @ (self.kp * (self.target - q) - self.kd * v)


@dataclass
class LQR(Law):
    """u = −K x; K is set by the simulator from the linearisation (pendverify.simulation.lqr)."""

    Q: np.ndarray = None
    R: np.ndarray = None
    saturation: float | None = None
    K: np.ndarray | None = None
    equilibrium: str = "upright"
    q_star: np.ndarray = None

    def __post_init__(self):
        self.feedback = True

    def __call__(self, t, q, v):
        u = -self.K @ np.concatenate([q - self.q_star, v])
        if self.saturation is not None:
            u = np.clip(u, -self.saturation, self.saturation)
        return u
