"""The perturbed parameter sets a repair is confirmed at (``pendverify.diagnosis.perturbed``).

Each set moves every parameter the description lets move, by 10–35 %, and rewrites the
description: the untouched model must then pass every check at each set, as it does at the
file's values (otherwise a right repair would be taken for a coincidence).  What cannot move is
named with its reason; equal values move together.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.bench.explain import class_targets, shipped_targets
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.corpus import CORPUS_SAMPLES, CORPUS_SEED
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.perturbed import LEAST_MOVE, MOST_MOVE, SETS, perturbations
from pendverify.symbolic.edited import edited_model
from pendverify.targets import plugin_target


def _passes_at_every_set(model, perturbation) -> None:
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    for moved in perturbation.sets:
        results = run_checks("moved", moved.model, moved.system, states, CORPUS_SEED,
                             applicable_checks(moved.model, moved.system))  # fmt: skip
        assert all(r.passed for r in results), (moved.params, [r for r in results if not r.passed])


def _moved_by(values: dict, moved) -> dict:
    return {k: math.log(getattr(moved, k) / v) for k, v in values.items() if v}


def test_equal_rods_move_in_groups_and_the_rewritten_urdf_agrees():
    ((_, model, system, _),) = [t for t in class_targets() if t[0].startswith("corpus_double_pendulum")]
    perturbation = perturbations(model, system)
    assert set(perturbation.groups) == {("m1", "m2"), ("lc1", "lc2"), ("I1", "I2"), ("l1", "l2")}
    assert perturbation.independent == ("g",) and perturbation.fixed == {}
    assert len(perturbation.sets) == SETS and perturbation.how == "the URDF rewritten for each"
    for moved in perturbation.sets:
        p = moved.params
        assert p.m1 == p.m2 != 1.0 and p.I1 == p.I2 and p.lc1 == p.lc2
        for name, log in _moved_by(model.params.as_dict(), p).items():
            assert LEAST_MOVE - 1e-12 <= abs(log) <= MOST_MOVE + 1e-12, name
    _passes_at_every_set(model, perturbation)


def test_furutas_tight_inertias_move_and_keep_the_triangle_inequality():
    """The arm's moments (1.7e-5, 1.043e-3, 1.057e-3) meet the triangle inequality almost with
    equality: moved each by its own factor they would break it, and the strict reader would refuse
    the URDF.  Moved through the second moments of mass, each moves and the URDF is read."""
    ((_, model, system, _),) = [t for t in shipped_targets() if t[0].startswith("furuta_pendulum, model (P")]
    perturbation = perturbations(model, system)
    assert len(perturbation.sets) == SETS and "Jrzz" in perturbation.independent
    for moved in perturbation.sets:
        p = moved.params
        assert p.Jrzz <= p.Jrxx + p.Jryy and p.Jpxx <= p.Jpyy + p.Jpzz
        assert all(getattr(p, n) != getattr(model.params, n) for n in ("Jrxx", "Jryy", "Jrzz"))
        assert not math.isclose(p.Jryy / model.params.Jryy, p.Jrzz / model.params.Jrzz, rel_tol=1e-6)
    _passes_at_every_set(model, perturbation)


ROD = """name = "rod_by_length"
inputs = ["tau"]
M = [["m*l**2/3"]]
C = [["0"]]
H = ["g*m*l*sin(theta)/2"]
B = [["1"]]
[coordinates]
theta = "angle"
[parameters]
m = { kind = "mass", unit = "kg" }
l = { kind = "length", unit = "m" }
g = { kind = "gravity", unit = "m/s²" }
[urdf]
joints = ["hinge"]
transform = [[1]]
offset = [0]
"""
ROD_PARAMS = """model = "rod_by_length"
[parameters]
m = 1.0
l = 0.5
g = 9.81
"""
#: the rod with its tip as a frame at l: the URDF holds l there, and l/2 and m·l²/12 elsewhere
ROD_URDF = """<robot name="rod">
  <link name="base"/>
  <joint name="hinge" type="continuous">
    <parent link="base"/><child link="rod"/><origin xyz="0 0 0"/><axis xyz="0 1 0"/>
  </joint>
  <link name="rod">
    <inertial>
      <origin xyz="0 0 -0.25"/><mass value="1.0"/>
      <inertia ixx="0.020833333333333332" ixy="0" ixz="0" iyy="0.020833333333333332" iyz="0" izz="0"/>
    </inertial>
  </link>
  <joint name="tip_joint" type="fixed"><parent link="rod"/><child link="tip"/><origin xyz="0 0 -0.5"/></joint>
  <link name="tip"/>
</robot>
"""


def test_a_parameter_the_urdf_also_holds_combined_is_not_moved(tmp_path):
    """l stands alone at the tip frame, and as l/2 and m·l²/12 in the rod's inertial: moving the
    tip alone makes entries that agree at the file's values disagree, so l is not moved, the
    repair of a sign in H is kept (not taken for a coincidence) and says why it is not confirmed."""
    for name, text in (("rod.toml", ROD), ("rod_params.toml", ROD_PARAMS), ("rod.urdf", ROD_URDF)):
        (tmp_path / name).write_text(text)
    target = plugin_target(
        str(tmp_path / "rod.toml"), str(tmp_path / "rod.urdf"), str(tmp_path / "rod_params.toml")
    )
    sm = SymbolicModel.of(type(target.model))
    original = sm.closed_forms["gravity"][0]
    planted = edited_model(target.model, sm, {"gravity": [(0, original, -original)]}, "Planted")
    states = sample_states(planted, CORPUS_SAMPLES, CORPUS_SEED)
    batch = CheckBatch(planted, target.system, states)
    results = run_checks("rod", planted, target.system, states, CORPUS_SEED,
                         applicable_checks(planted, target.system), batch)  # fmt: skip
    first = next(f for f in explain(batch, results) if f.kind == "repair")
    assert first.details["checks_pass"] and not first.details["confirmed"], first.message
    assert sp.simplify(sp.sympify(first.details["suggested"]) - sp.sympify(str(original))) == 0
    assert (
        "l was not moved (moved in the URDF, entries that agree at the file's values disagree"
        in first.message
    )


@pytest.mark.parametrize("draws", [1, 2])
def test_the_sets_are_the_same_every_time(draws):
    ((_, model, system, _),) = [t for t in shipped_targets() if t[0].startswith("cart_pole, model (P")]
    first, again = perturbations(model, system, count=draws), perturbations(model, system, count=draws)
    assert [s.params for s in first.sets] == [s.params for s in again.sets]
    assert np.all([s.params != model.params for s in first.sets])
