"""Repairs confirmed on a description that is not rewritten: the parameters moved in its Pinocchio model.

An MJCF (SDFormat, a ``pinocchio.Model``) is not rewritten; each perturbed set moves the
parameters in the Pinocchio model read from it (``pendverify.robot.model_rebind``), so a repair
is confirmed there as on a URDF.  Each test plants one error in a model checked against an MJCF
and asserts what the repair says: the exact edit confirmed, a coincidence of the file's values
caught at the moved sets, and a parameter the model holds nowhere alone left unmoved with its
reason.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from pendverify.analytic import DoublePendulum
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.bench.explain import class_targets, shipped_targets
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.corpus import CORPUS_SAMPLES, CORPUS_SEED
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.perturbed import SETS, perturbations
from pendverify.errors import RebindError
from pendverify.robot.model_rebind import ModelBinding
from pendverify.robot.pinocchio_model import describe_model
from pendverify.robot.system import PinocchioSystem
from pendverify.symbolic.edited import edited_model
from pendverify.targets import plugin_target, select_targets

from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
#: the words only a confirmed repair is printed with (``test_confirmed``)
CONFIRMED_WORDS = "at these parameter values and at"
MOVED = "(the MJCF's Pinocchio model moved for each)"

#: the classic cart-pole of examples/corpus_cart_pole.urdf in MJCF: I = mp·l²/3 (a uniform pole
#: of length 2l about its centre), so 4·I gives the numbers of I + mp·l²; the pole's moment about
#: its own axis is 1e-6 kg·m² (MuJoCo wants every moment > 0; it never spins about it)
CART_POLE_MJCF = """<mujoco model="corpus_cart_pole">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="cart">
      <joint name="cart_slider" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="1.0" diaginertia="0.01 0.01 0.01"/>
      <body name="pole">
        <joint name="pole_hinge" type="hinge" axis="0 -1 0"/>
        <inertial pos="0 0 -0.5" mass="0.1" diaginertia="0.008333333333333333 0.008333333333333333 1e-6"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""

#: examples/corpus_pendulum_rod.urdf in MJCF, its body frame turned by PHI about the hinge (y): the
#: centre of mass is the same point (0.25 m straight down at θ = 0) but its components in the
#: body's frame are 0.25·sin φ and 0.25·cos φ, so the model holds lc nowhere alone.  The inertia's
#: axes stay the body's: turned about the hinge, its moment about the hinge is the same I
PHI = 0.4
ROD_MJCF = f"""<mujoco model="corpus_pendulum_rod">
  <compiler angle="radian" inertiafromgeom="false"/>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="rod" quat="{math.cos(PHI / 2)!r} 0 {math.sin(PHI / 2)!r} 0">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="0.1"/>
      <inertial pos="{0.25 * math.sin(PHI)!r} 0 {-0.25 * math.cos(PHI)!r}" mass="1.0"
                diaginertia="0.020833333333333332 0.020833333333333332 1e-6"/>
    </body>
  </worldbody>
</mujoco>
"""


def _mjcf_target(tmp_path, model: str, text: str, params: str):
    """The target of the shipped model file ``model`` and parameter file ``params`` on MJCF ``text``."""
    path = tmp_path / "robot.mjcf.xml"
    path.write_text(text)
    return plugin_target(str(EXAMPLES / model), str(path), str(EXAMPLES / params))


def _repairs(model, system, method: str, index: int, planted: str):
    """The repair findings of ``model`` on ``system`` with entry ``index`` of ``method`` replaced
    by ``planted`` (SymPy syntax over the model's names)."""
    sm = SymbolicModel.of(type(model))
    names = {s.name: s for group in sm.symbols.values() for s in group}
    names |= {p.name: p for p in sm.parameters.values()}
    value = sm.closed_forms[method]
    original = value[index] if isinstance(value, sp.MatrixBase) else value
    model = edited_model(model, sm, {method: [(index, original, sp.sympify(planted, locals=names))]}, "P")
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks(
        "planted", model, system, states, CORPUS_SEED, applicable_checks(model, system), batch
    )
    assert not all(r.passed for r in results), "the planted error must fail a check"
    findings = [f for f in explain(batch, results) if f.kind == "repair"]
    for f in findings:  # the confirmed words belong to a confirmed repair only
        assert (CONFIRMED_WORDS in f.message) is bool(f.details.get("confirmed")), f.message
    return findings


def _same(suggested: str, expected: str) -> bool:
    return sp.expand(sp.sympify(suggested) - sp.sympify(expected)) == 0


def _passes_at_every_set(model, perturbation) -> None:
    """The untouched model passes every check at each moved set, as at the file's values."""
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    for moved in perturbation.sets:
        results = run_checks("moved", moved.model, moved.system, states, CORPUS_SEED,
                             applicable_checks(moved.model, moved.system))  # fmt: skip
        assert all(r.passed for r in results), (moved.params, [r for r in results if not r.passed])


def test_the_double_pendulums_mjcf_moves_its_parameters_and_confirms_the_repair():
    """examples/double_pendulum.mjcf.xml: every parameter the model holds moves (l2 is a drawing
    length, held nowhere); the untouched model passes at each set; I2 dropped from M[2,2] is
    repaired by I2 + m2·r2², confirmed (before: it held "at these parameter values" only)."""
    params = default_params("double_pendulum")
    system = PinocchioSystem.for_model(DoublePendulum, EXAMPLES / "double_pendulum.mjcf.xml", params.g)
    model = DoublePendulum(params)
    perturbation = perturbations(model, system)
    assert set(perturbation.independent) == {"m1", "m2", "l1", "r1", "r2", "I1", "I2", "b1", "b2", "g"}
    assert perturbation.how == "the MJCF's Pinocchio model moved for each"
    assert len(perturbation.sets) == SETS
    for moved in perturbation.sets:  # the moved model holds the moved values, read back by its reader
        read = moved.system.geometry.params
        for name in ("m1", "m2", "l1", "r1", "r2", "I1", "I2", "b1", "b2"):
            assert math.isclose(getattr(read, name), getattr(moved.params, name), rel_tol=1e-12), name
            assert getattr(moved.params, name) != getattr(params, name), name
        assert moved.system.urdf_damping().tolist() == [moved.params.b1, moved.params.b2]
    _passes_at_every_set(model, perturbation)
    findings = _repairs(model, system, "mass_matrix", 3, "r2**2*m2")
    first = findings[0]
    assert first.details["confirmed"], first.message
    assert _same(first.details["suggested"], "I2 + m2*r2**2"), first.message
    assert MOVED in first.message


def test_a_coincidence_of_an_mjcfs_values_is_caught_at_the_moved_sets(tmp_path):
    """The cart-pole in MJCF, I = mp·l²/3: with mp·l² missing from M[2,2], 4·I makes every check
    pass at the file's values; the moved sets catch it, and I + mp·l² is confirmed.  Before the
    parameters moved in the model, 4·I was printed as holding and nothing was confirmed."""
    target = _mjcf_target(tmp_path, "corpus_cart_pole_latex.toml", CART_POLE_MJCF, "corpus_cart_pole.toml")
    findings = _repairs(target.model, target.system, "mass_matrix", 3, "I")
    first = findings[0]
    assert first.details["confirmed"], first.message
    assert _same(first.details["suggested"], "I + l**2*mp"), first.message
    assert MOVED in first.message
    assert not any(f.details["suggested"] and _same(f.details["suggested"], "4*I") for f in findings)


def test_a_parameter_the_model_holds_nowhere_alone_stays_unmoved_with_its_reason(tmp_path):
    """The rod in a turned body frame: lc is in the model only as 0.25·sin φ and 0.25·cos φ, so
    it is not moved, and says why.  m, I and b move: with m·lc² missing from M, 4·I (I = m·lc²/3
    here) is caught, I + m·lc² holds and is not confirmed, naming lc's reason."""
    target = _mjcf_target(tmp_path, "corpus_pendulum_rod.toml", ROD_MJCF, "corpus_pendulum_rod_params.toml")
    perturbation = perturbations(target.model, target.system)
    assert perturbation.fixed == {
        "lc": "its value 0.25 is not in the Pinocchio model's centres of mass (inertias[j].lever) "
        "or joint placements (jointPlacements[j].translation)"
    }
    assert set(perturbation.independent) == {"m", "I", "b", "g"} and len(perturbation.sets) == SETS
    _passes_at_every_set(target.model, perturbation)
    findings = _repairs(target.model, target.system, "mass_matrix", 0, "I")
    first = findings[0]
    assert _same(first.details["suggested"], "I + lc**2*m") and not first.details["confirmed"], first.message
    assert "not confirmed: lc was not moved (its value 0.25 is not in the Pinocchio model's" in first.message
    assert not any(f.details["suggested"] and _same(f.details["suggested"], "4*I") for f in findings)


def test_where_a_parameter_cannot_move_the_ambiguity_is_stated(tmp_path):
    """The turned rod with m·lc for m·lc² in M: lc is not moved, so I + m·lc/4 and I + m·lc² both
    hold at every set; neither is confirmed, and the message says under which relation they agree."""
    target = _mjcf_target(tmp_path, "corpus_pendulum_rod.toml", ROD_MJCF, "corpus_pendulum_rod_params.toml")
    findings = _repairs(target.model, target.system, "mass_matrix", 0, "I + m*lc")
    assert not any(f.details["confirmed"] for f in findings)
    first = findings[0]
    assert "not confirmed: lc was not moved (its value 0.25 is not in the Pinocchio model's" in first.message
    assert "holds as well: they differ unless lc = 1/4" in first.message
    suggested = [f.details["suggested"] for f in findings]
    assert any(_same(s, "I + lc**2*m") for s in suggested) and any(_same(s, "I + lc*m/4") for s in suggested)


def test_an_edit_whose_number_stands_for_an_unmoved_parameter_is_not_confirmed(tmp_path):
    """The turned rod with lc dropped from H: g·m·sin θ/4 (lc = 0.25, never moved) holds at every set
    and involves only moved parameters; it is not confirmed, the message naming lc as the model's
    unmoved parameter.  A parameter of the URDF rod that moves is still confirmed (the same plant on
    the URDF, where lc moves, gets g·lc·m·sin θ confirmed)."""
    target = _mjcf_target(tmp_path, "corpus_pendulum_rod.toml", ROD_MJCF, "corpus_pendulum_rod_params.toml")
    findings = _repairs(target.model, target.system, "gravity", 0, "g*m*sin(theta)")
    assert not any(f.details["confirmed"] for f in findings)
    assert "lc of your model was not moved (lc: its value 0.25 is not in" in findings[0].message
    assert "so an edit whose numbers stand for its value holds at every set as well" in findings[0].message
    urdf = [t for t in class_targets() if t[0].startswith("corpus_pendulum_rod")]
    ((_, model, system, _),) = urdf
    (first, *_) = _repairs(model, system, "gravity", 0, "g*m*sin(theta)")
    assert first.details["confirmed"] and _same(first.details["suggested"], "g*lc*m*sin(theta)"), (
        first.message
    )


def test_a_pinocchio_model_given_to_the_api_moves_its_parameters(tmp_path):
    """The same cart-pole given as a ``pinocchio.Model`` (no file at all): its repair is confirmed
    as the MJCF's, the model moved for each set."""
    target = _mjcf_target(tmp_path, "corpus_cart_pole_latex.toml", CART_POLE_MJCF, "corpus_cart_pole.toml")
    selection = select_targets(type(target.model), describe_model(target.system.model), target.model.params)
    (given,) = selection.targets
    assert given.system.urdf.format == "pinocchio"
    perturbation = perturbations(given.model, given.system)
    assert set(perturbation.independent) == {"mc", "mp", "l", "I", "g"} and len(perturbation.sets) == SETS
    assert perturbation.how == "the Pinocchio model moved for each"
    findings = _repairs(given.model, given.system, "mass_matrix", 3, "I")
    assert findings[0].details["confirmed"] and _same(findings[0].details["suggested"], "I + l**2*mp")


def test_an_sdformat_description_moves_its_parameters():
    """Drake's Acrobot.sdf (``tests/robot/test_drake_sdf.py``), read through Drake into Pinocchio:
    its masses, lengths and inertias move, and the untouched hand model passes at each set.
    Skipped when pydrake is not installed."""
    pytest.importorskip("pydrake.common")
    from ..robot.test_drake_sdf import ACROBOT, ACROBOT_PARAMS, DrakeAcrobot

    (target,) = select_targets(DrakeAcrobot, ACROBOT, ACROBOT_PARAMS).targets
    perturbation = perturbations(target.model, target.system)
    assert perturbation.how == "the SDFormat's Pinocchio model moved for each"
    moved = set(perturbation.independent) | {n for group in perturbation.groups for n in group}
    assert {"m1", "m2", "I1", "I2", "r1"} <= moved and len(perturbation.sets) == SETS
    _passes_at_every_set(target.model, perturbation)


#: a rod pendulum whose hinge carries a rotor of inertia a (MuJoCo's armature, on M's diagonal)
ROTOR_MODEL = """name = "rod_with_rotor"
inputs = ["tau"]
M = [["I + m*lc**2 + a"]]
C = [["0"]]
H = ["g*m*lc*sin(theta)"]
B = [["1"]]
[coordinates]
theta = "angle"
[parameters]
m = { kind = "mass", unit = "kg" }
lc = { kind = "offset", unit = "m" }
I = { kind = "inertia", unit = "kg·m²" }
a = { kind = "inertia", unit = "kg·m²" }
g = { kind = "gravity", unit = "m/s²" }
[urdf]
joints = ["hinge"]
transform = [[1]]
offset = [0]
"""
ROTOR_PARAMS = """model = "rod_with_rotor"
[parameters]
m = 1.0
lc = 0.25
I = 0.020833333333333332
a = 0.003
g = 9.81
"""
ROTOR_MJCF = """<mujoco model="rod_with_rotor">
  <compiler angle="radian" inertiafromgeom="false"/>
  <worldbody>
    <body name="rod">
      <joint name="hinge" type="hinge" axis="0 1 0" armature="0.003"/>
      <inertial pos="0 0 -0.25" mass="1.0" diaginertia="0.020833333333333332 0.020833333333333332 1e-6"/>
    </body>
  </worldbody>
</mujoco>
"""


def test_an_armature_moves_in_the_model_and_m_follows(tmp_path):
    """The rotor's a is the MJCF's armature, which Pinocchio adds to M's diagonal: it moves in
    ``model.armature``, the untouched model passes at each set, and with a dropped from M the
    repair I + m·lc² + a is confirmed."""
    for name, text in (("rotor.toml", ROTOR_MODEL), ("rotor_params.toml", ROTOR_PARAMS)):
        (tmp_path / name).write_text(text)
    (tmp_path / "rotor.mjcf.xml").write_text(ROTOR_MJCF)
    target = plugin_target(
        str(tmp_path / "rotor.toml"), str(tmp_path / "rotor.mjcf.xml"), str(tmp_path / "rotor_params.toml")
    )
    perturbation = perturbations(target.model, target.system)
    assert set(perturbation.independent) == {"m", "lc", "I", "a", "g"} and len(perturbation.sets) == SETS
    for moved in perturbation.sets:
        assert moved.system.model.armature.tolist() == [moved.params.a] != [0.003]
    _passes_at_every_set(target.model, perturbation)
    findings = _repairs(target.model, target.system, "mass_matrix", 0, "I + m*lc**2")
    assert findings[0].details["confirmed"] and _same(findings[0].details["suggested"], "I + m*lc**2 + a")


def test_equal_rods_move_in_groups_in_the_pinocchio_model():
    """The double pendulum of two equal rods given as a ``pinocchio.Model``: m1 = m2, lc1 = lc2,
    I1 = I2 and l1 = l2 share their values and sites there as in its URDF, so each pair moves by
    one factor and stays equal (``rebind.match``'s groups, whatever holds the values)."""
    ((_, model, system, _),) = [t for t in class_targets() if t[0].startswith("corpus_double_pendulum")]
    (given,) = select_targets(type(model), describe_model(system.model), model.params).targets
    perturbation = perturbations(given.model, given.system)
    assert set(perturbation.groups) == {("m1", "m2"), ("lc1", "lc2"), ("I1", "I2"), ("l1", "l2")}
    assert perturbation.independent == ("g",) and perturbation.fixed == {} and len(perturbation.sets) == SETS
    for moved in perturbation.sets:
        p = moved.params
        assert p.m1 == p.m2 != model.params.m1 and p.I1 == p.I2 != model.params.I1 and p.lc1 == p.lc2
    _passes_at_every_set(given.model, perturbation)


def test_furutas_tight_inertias_move_in_its_pinocchio_model_and_stay_a_rigid_bodys():
    """Furuta's pendulum given as a ``pinocchio.Model``: its arm's moments (1.7e-5, 1.043e-3,
    1.057e-3) meet the triangle inequality almost with equality.  Each is bound alone to a diagonal
    entry of the arm's rotational inertia, so the three move through the second moments of mass
    (``perturbed``), as in its URDF: each moves, their ratios differ, the inequality holds, and the
    untouched model passes at each set."""
    ((_, model, system, _),) = [t for t in shipped_targets() if t[0].startswith("furuta_pendulum, model (P")]
    (given,) = select_targets(type(model), describe_model(system.model), model.params).targets
    perturbation = perturbations(given.model, given.system)
    assert len(perturbation.sets) == SETS and {"Jrxx", "Jryy", "Jrzz"} <= set(perturbation.independent)
    for moved in perturbation.sets:
        p = moved.params
        assert p.Jrzz <= p.Jrxx + p.Jryy and p.Jpxx <= p.Jpyy + p.Jpzz
        assert all(getattr(p, n) != getattr(model.params, n) for n in ("Jrxx", "Jryy", "Jrzz"))
        assert not math.isclose(p.Jryy / model.params.Jryy, p.Jrzz / model.params.Jrzz, rel_tol=1e-6)
        arm = moved.system.model.inertias[1].inertia
        assert np.allclose(np.diag(arm), [p.Jrxx, p.Jryy, p.Jrzz], rtol=1e-12, atol=0), (arm, p)
    _passes_at_every_set(given.model, perturbation)


#: a double pendulum whose link 1 is a uniform rod given by its length l: its centre of mass at
#: l/2 and inertia m1·l²/12, joint 2 at l (examples/corpus_double_pendulum.toml otherwise)
BY_LENGTH_MODEL = """name = "rod_and_pendulum"
inputs = ["tau1", "tau2"]
M = [
  [
    "m1*l**2/12 + I2 + m1*l**2/4 + m2*(l**2 + lc2**2 + 2*l*lc2*cos(theta2))",
    "I2 + m2*(lc2**2 + l*lc2*cos(theta2))",
  ],
  ["I2 + m2*(lc2**2 + l*lc2*cos(theta2))", "I2 + m2*lc2**2"],
]
C = [
  ["-m2*l*lc2*sin(theta2)*dtheta2", "-m2*l*lc2*sin(theta2)*(dtheta1 + dtheta2)"],
  ["m2*l*lc2*sin(theta2)*dtheta1", "0"],
]
H = ["g*((m1*l/2 + m2*l)*sin(theta1) + m2*lc2*sin(theta1 + theta2))", "g*m2*lc2*sin(theta1 + theta2)"]
B = [["1", "0"], ["0", "1"]]
[coordinates]
theta1 = "angle"
theta2 = "angle"
[parameters]
m1 = { kind = "mass", unit = "kg" }
m2 = { kind = "mass", unit = "kg" }
l = { kind = "length", unit = "m" }
lc2 = { kind = "offset", unit = "m" }
I2 = { kind = "inertia", unit = "kg·m²" }
g = { kind = "gravity", unit = "m/s²" }
[urdf]
joints = ["joint1", "joint2"]
transform = [[1, 0], [0, 1]]
offset = [0, 0]
"""
BY_LENGTH_PARAMS = """model = "rod_and_pendulum"
[parameters]
m1 = 1.0
m2 = 0.7
l = 0.6
lc2 = 0.35
I2 = 0.004
g = 9.81
"""
BY_LENGTH_MJCF = """<mujoco model="rod_and_pendulum">
  <compiler angle="radian" inertiafromgeom="false"/>
  <worldbody>
    <body name="link1">
      <joint name="joint1" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 -0.3" mass="1.0" diaginertia="0.03 0.03 1e-6"/>
      <body name="link2" pos="0 0 -0.6">
        <joint name="joint2" type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 -0.35" mass="0.7" diaginertia="0.004 0.004 1e-6"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_parameter_the_model_holds_alone_and_combined_is_not_moved(tmp_path):
    """l is joint 2's placement alone, and l/2, m1·l²/12 in link 1's inertia: moved alone, it makes
    entries that agree at the file's values disagree, so it is not moved (nor m1, which
    m1·l²/12 holds combined), and the repair of a sign in M[1,2] is kept, not confirmed, saying why."""
    for name, text in (
        ("m.toml", BY_LENGTH_MODEL),
        ("p.toml", BY_LENGTH_PARAMS),
        ("r.mjcf.xml", BY_LENGTH_MJCF),
    ):
        (tmp_path / name).write_text(text)
    target = plugin_target(str(tmp_path / "m.toml"), str(tmp_path / "r.mjcf.xml"), str(tmp_path / "p.toml"))
    assert perturbations(target.model, target.system).independent == ("m1", "m2", "l", "lc2", "I2", "g")
    findings = _repairs(target.model, target.system, "mass_matrix", 1, "I2 + m2*(lc2**2 - l*lc2*cos(theta2))")
    first = findings[0]
    assert _same(first.details["suggested"], "I2 + m2*(lc2**2 + l*lc2*cos(theta2))"), first.message
    assert not first.details["confirmed"], first.message
    assert (
        "l was not moved (moved in the Pinocchio model, entries that agree at the file's values disagree: "
        "the Pinocchio model holds it combined with other parameters too)"
    ) in first.message


def test_an_inertia_moved_in_the_model_stays_a_rigid_bodys(tmp_path):
    """Moved alone, the rod's I (its two moments across the rod) keeps the triangle inequality
    with the 1e-6 axial moment; a move that would break it is refused by joint, not kept."""
    target = _mjcf_target(tmp_path, "corpus_pendulum_rod.toml", ROD_MJCF, "corpus_pendulum_rod_params.toml")
    params = target.model.params
    binding = ModelBinding.of(target.system.urdf, params)
    assert [s.attribute for _, s in binding.sites["I"]] == ["ixx", "iyy"]
    moved = binding.rewrite(params.replace(I=params.I * 1.3)).model
    assert math.isclose(moved.inertias[1].inertia[1, 1], params.I * 1.3, rel_tol=1e-12)
    assert moved.inertias[1].lever.tolist() == target.system.urdf.model.inertias[1].lever.tolist()
    assert target.system.urdf.model.inertias[1].inertia[1, 1] == pytest.approx(params.I, rel=1e-12)
    with pytest.raises(
        RebindError, match=r"joint 'hinge': the moved rotational inertia has principal moments"
    ):
        binding.rewrite(params.replace(I=1e-9))  # 1e-9 + 1e-9 < the axial 1e-6: no rigid body
