"""The bounds of the battery's settings: one rule for ``certify``'s options and a certificate's ``settings``.

* ``samples``: a whole number from 1 to the sample limit (``PENDVERIFY_MAX_SAMPLES``,
  ``pendverify.simulation.limits``; default 1 000 000), so a certificate asking for
  10**7 states is refused with its key and the limit instead of exhausting memory;
* ``seed``: a whole number from 0 to 2**64 - 1 (what a seed of NumPy's generator is made of);
* ``sim_duration`` (s, per simulated effect) and ``sim_rtol``: finite numbers > 0.

``settings_problem`` says what is wrong with one value ("" when nothing is), so the
command line (``samples_option``, ``seed_option``: argparse types) and ``recheck``
(``pendverify.certify.schema``) apply the same bounds.
"""

from __future__ import annotations

import argparse
import math

from pendverify.simulation.limits import MAX_SAMPLES_VARIABLE, max_samples

MAX_SEED = 2**64 - 1


def _whole(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _positive_finite(value) -> bool:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(float(value)) and value > 0
    except OverflowError:  # an integer beyond float's range
        return False


def settings_problem(key: str, value) -> str:
    """What ``value`` of setting ``key`` breaks ("" if nothing): the rule, with its bounds."""
    if key == "samples":
        limit = max_samples()
        if not _whole(value) or not 1 <= value <= limit:
            return (
                f"expected a whole number of states from 1 to the limit {limit:,} "
                f"(raise the limit with {MAX_SAMPLES_VARIABLE})"
            )
    elif key == "seed":
        if not _whole(value) or not 0 <= value <= MAX_SEED:
            return "expected a whole number from 0 to 2**64 - 1"
    elif key in ("sim_duration", "sim_rtol"):
        if not _positive_finite(value):
            return "expected a finite number > 0"
    return ""


def _option(key: str, text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    problem = settings_problem(key, value)
    if problem:
        raise argparse.ArgumentTypeError(f"{value}: {problem}")
    return value


def samples_option(text: str) -> int:
    """``--samples N`` of certify: the battery's ``samples`` rule."""
    return _option("samples", text)


def seed_option(text: str) -> int:
    """``--seed N`` of certify: the battery's ``seed`` rule."""
    return _option("seed", text)
