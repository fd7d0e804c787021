"""Bounded work: a scene's samples and fixed steps are counted before anything is allocated.

``duration = 1e9`` at 100 Hz would ask for 1e11 samples (745 GiB of times alone);
``rk4`` with ``step = 1e-9`` over 10 s for 1e10 steps.  Both counts — the output
samples, duration × sample_rate + 1, and the fixed steps, duration / step — must be
at most the limit, ``PENDVERIFY_MAX_SAMPLES`` in the environment (default
1 000 000, a few hundred MB at most and minutes of integration).  A scene beyond it
is refused with one line naming the key, the estimate and the limit.

An adaptive method's steps cannot be counted before the run: they depend on how
fast the dynamics move (``gravity = 1e9`` asks RK45 for millions of steps of a
few microseconds each).  They are counted as they are taken, and a run that
takes more than the scene's ``integrator.max_steps`` (default
``DEFAULT_MAX_STEPS``) stops with one line naming the key, the limit and how far
it got.  The default, 100 000, is over 100 times the most any shipped scene takes (817,
``chaotic_double_pendulum``: DOP853 over 10 s) — 10 000 steps a second of
simulated time over a 10 s scene — and at the 2 500 steps a second a double
pendulum runs on one core stops a run in under a minute.
"""

from __future__ import annotations

import math
import os

from pendverify.errors import InputError, SceneError

MAX_SAMPLES_VARIABLE = "PENDVERIFY_MAX_SAMPLES"
DEFAULT_MAX_SAMPLES = 1_000_000
#: the adaptive steps a run may take unless its scene sets ``integrator.max_steps`` (docstring)
DEFAULT_MAX_STEPS = 100_000
#: float64 values kept per output sample and state entry (t, x, the invariants' arrays), a rough bound
_BYTES_PER_VALUE = 8 * 4


def environment_limit(variable: str, default: int, minimum: int = 1) -> int:
    """A work limit from the environment variable ``variable`` (a whole number >= ``minimum``), else
    ``default``."""
    text = os.environ.get(variable)
    if text is None or text.strip() == "":
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= minimum and value == int(value)):
        raise InputError("<environment>", variable, text, f"must be a whole number >= {minimum}, e.g. 5e6")
    return int(value)


def max_samples() -> int:
    """The limit on samples and on fixed steps: ``PENDVERIFY_MAX_SAMPLES``, else the default."""
    return environment_limit(MAX_SAMPLES_VARIABLE, DEFAULT_MAX_SAMPLES)


def check_scene_work(source: str, duration: float, sample_rate: float, step: float | None, nx: int) -> None:
    """Refuse a scene whose output samples or fixed steps (``integrator.step``) exceed the limit."""
    limit = max_samples()
    samples = duration * sample_rate + 1  # floats: the product may overflow to inf
    if samples > limit:
        size = samples * (1 + nx) * _BYTES_PER_VALUE
        raise SceneError(
            source,
            "time",
            f"duration = {duration:g}, sample_rate = {sample_rate:g}",
            f"duration × sample_rate ≈ {samples:.3g} output samples (≈ {_bytes(size)}) exceed the limit "
            f"of {limit:g}; lower duration or sample_rate, "
            f"or raise the limit with {MAX_SAMPLES_VARIABLE}",
        )
    if step is not None:
        steps = duration / step
        if steps > limit:
            raise SceneError(
                source,
                "integrator.step",
                step,
                f"duration / step = {duration:g} s / {step:g} s ≈ {steps:.3g} fixed steps exceeds the "
                f"limit of {limit:g}; use a larger step, or raise the limit with {MAX_SAMPLES_VARIABLE}",
            )


def _bytes(n: float) -> str:
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB"):
        if n < 1024 or unit == "PiB":
            return f"{n:.3g} {unit}"
        n /= 1024
    return f"{n:.3g} PiB"  # pragma: no cover
