"""How well a trap explains a failure: the thresholds and the words the diagnoses share.

The *residual* of a hypothesis is the part of the discrepancy it leaves unexplained,
relative to the whole.  A residual at rounding level (≤ ``EXACT_RESIDUAL``) is an exact
fit; up to ``FIT_RESIDUAL`` (1e-3) the trap is named with its residual and the sentence
says that a smaller difference remains (a URDF rotation written as 3.1416 for π leaves
7e-6); beyond it the hypothesis is not named.  Each hypothesis is tested on the
special states and ``DIAGNOSIS_STATES`` random ones drawn with ``DIAGNOSIS_SEED``.
"""

from __future__ import annotations

from pendverify.checks.sampling import sample_states

EXACT_RESIDUAL = 1e-9  # a residual at rounding level (of the fitted data, ~1e-15, with margin)
FIT_RESIDUAL = 1e-3  # the most a named trap may leave unexplained
DIAGNOSIS_STATES = 8  # random states per hypothesis, besides the special ones
DIAGNOSIS_SEED = 4242


def diagnosis_states(model):
    """The states every hypothesis is tested on."""
    return sample_states(model, DIAGNOSIS_STATES, DIAGNOSIS_SEED)


def fmt(values) -> str:
    """A vector as "(a, b, c)" with six significant digits."""
    return "(" + ", ".join(f"{x:.6g}" for x in values) + ")"


def fit_words(residual: float) -> str:
    """How well a pattern fits, in words, with its residual."""
    if residual <= EXACT_RESIDUAL:
        return "exactly"
    return f"up to a relative residual of {residual:.2g} (a smaller difference remains as well)"
