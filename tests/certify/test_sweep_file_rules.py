"""A sweep file's rules, one per case: each bad key gives its one sentence (file, key, value, rule).

The sentences are the ones ``load_sweep`` gave before its checks became a ``pendverify.documents``
schema (``SWEEP``, ``RANGE``): the schema must keep every one of them.
"""

from __future__ import annotations

import pytest

from pendverify.certify.sweep import load_sweep
from pendverify.errors import SweepError

CASES = [
    (
        'model = "double_pendulum"\ncolour = 1\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'colour' = 1: unknown key; expected one of "
        "model, base, urdf, mode, count, seed, samples, duration, ranges",
    ),
    (
        'model = "double_pendulum"\nbase = 3\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'base' = 3: expected \"default\" or a parameter file (a string)",
    ),
    (
        'model = "double_pendulum"\nbase = ""\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'base' = '': expected \"default\" or a parameter file (a string)",
    ),
    (
        'model = "double_pendulum"\nmode = "spiral"\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'mode' = 'spiral': expected random or grid",
    ),
    (
        'model = "double_pendulum"\nmode = 1\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'mode' = 1: expected random or grid",
    ),
    (
        'model = "double_pendulum"\ncount = 0\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'count' = 0: expected an integer >= 1",
    ),
    (
        'model = "double_pendulum"\ncount = true\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'count' = True: expected an integer >= 1",
    ),
    (
        'model = "double_pendulum"\ncount = 2.5\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'count' = 2.5: expected an integer >= 1",
    ),
    (
        'model = "double_pendulum"\nseed = -1\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'seed' = -1: expected a whole number from 0 to 2**64 - 1",
    ),
    (
        'model = "double_pendulum"\nsamples = 0\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'samples' = 0: expected a whole number of states from 1 to the limit 1,000,000 "
        "(raise the limit with PENDVERIFY_MAX_SAMPLES)",
    ),
    (
        'model = "double_pendulum"\nduration = 0\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'duration' = 0: expected a finite number > 0 (s, per simulated effect)",
    ),
    (
        'model = "double_pendulum"\nduration = "x"\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'duration' = 'x': expected a finite number > 0 (s, per simulated effect)",
    ),
    ('model = "double_pendulum"\n', "key 'ranges' = None: expected a table of at least one parameter range"),
    (
        'model = "double_pendulum"\n[ranges]\n',
        "key 'ranges' = {}: expected a table of at least one parameter range",
    ),
    (
        'model = "double_pendulum"\nranges = 3\n',
        "key 'ranges' = 3: expected a table of at least one parameter range",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = [0.5]\n',
        "key 'ranges.m1' = [0.5]: expected [min, max] or a table {min, max, ...}",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = "a"\n',
        "key 'ranges.m1' = 'a': expected [min, max] or a table {min, max, ...}",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = [0.5, "x"]\n',
        "key 'ranges.m1.max' = 'x': expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = [true, 2.0]\n',
        "key 'ranges.m1.min' = True: expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = [2.0, 0.5]\n',
        "key 'ranges.m1' = [2.0, 0.5]: expected min <= max",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0 }\n',
        "key 'ranges.m1.max' = None: expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { max = 1.0 }\n',
        "key 'ranges.m1.min' = None: expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0, max = 2.0, step = 1 }\n',
        "key 'ranges.m1.step' = 1: unknown key; expected min, max, scale, points",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0, max = 2.0, scale = "cubic" }\n',
        "key 'ranges.m1.scale' = 'cubic': expected linear or log",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 0.0, max = 2.0, scale = "log" }\n',
        "key 'ranges.m1.min' = 0.0: a log range needs min > 0",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0, max = 2.0, points = 0 }\n',
        "key 'ranges.m1.points' = 0: expected an integer >= 1",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0, max = 2.0, points = 1.5 }\n',
        "key 'ranges.m1.points' = 1.5: expected an integer >= 1",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = nan, max = 2.0 }\n',
        "key 'ranges.m1.min' = nan: expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nm1 = { min = 1.0, max = inf }\n',
        "key 'ranges.m1.max' = inf: expected a finite number",
    ),
    (
        'model = "double_pendulum"\n[ranges]\nmass = [1.0, 2.0]\n',
        "key 'ranges.mass' = [1.0, 2.0]: unknown parameter; "
        "double_pendulum has m1, m2, l1, l2, r1, r2, I1, I2, b1, b2, g",
    ),
    (
        'model = "nope"\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'model' = 'nope': expected a model file (.py) or one of double_pendulum, cart_double_pendulum",
    ),
    (
        "model = 3\n[ranges]\nm1 = [0.5, 2.0]\n",
        "key 'model' = 3: expected a model file (.py) or one of double_pendulum, cart_double_pendulum",
    ),
    (
        'model = "double_pendulum"\nurdf = "a.urdf"\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'urdf' = 'a.urdf': a built-in model's sets use the URDF the project writes",
    ),
    (
        'model = "double_pendulum"\ncount = 1000000\n[ranges]\nm1 = [0.5, 2.0]\n',
        "key 'count' = 1000000: 1,000,000 sets exceed the limit of 1,000; raise it with --max-sets N",
    ),
]


BEYOND_A_DOUBLE = "9" * 310  # a TOML integer float() overflows on (NumPy's isfinite raised TypeError on it)
CASES.append(
    (
        f'model = "double_pendulum"\n[ranges]\nm1 = [0.5, {BEYOND_A_DOUBLE}]\n',
        f"key 'ranges.m1.max' = {BEYOND_A_DOUBLE}: expected a finite number",
    )
)


@pytest.mark.parametrize(("text", "sentence"), CASES)
def test_each_rule_has_its_sentence(tmp_path, monkeypatch, text, sentence):
    monkeypatch.delenv("PENDVERIFY_MAX_SAMPLES", raising=False)  # the limit the samples sentence names
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(text)
    with pytest.raises(SweepError) as caught:
        load_sweep(sweep, max_sets=1000)
    assert str(caught.value) == f"{sweep}: {sentence}"


def test_the_defaults_are_the_documented_ones(tmp_path):
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'model = "double_pendulum"\n[ranges]\nm1 = [0.5, 2.0]\nm2 = { min = 1.0, max = 4.0, scale = "log" }\n'
    )
    loaded = load_sweep(sweep)
    assert (len(loaded.sets), loaded.sets.mode, loaded.sets.seed) == (100, "random", 0)
    assert (loaded.settings.samples, loaded.settings.sim_duration) == (200, 1.0)
    assert loaded.sets.specs == {"m1": (0.5, 2.0, "linear", 3), "m2": (1.0, 4.0, "log", 3)}
