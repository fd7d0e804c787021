"""The matrix's own generator, validated without pendverify: its closed forms against Pinocchio's
CRBA and RNEA on the URDF it writes, against MuJoCo on the MJCF it writes, and the Christoffel C
against Kane's forcing.

These test the tests: a cell of the matrix is only evidence about pendverify if the closed forms
and the robot descriptions it hands pendverify agree with each other.  Tolerance: every quantity
is a sum of a few dozen products of parameters of order 1 and sines/cosines, evaluated in double
precision by two different algorithms; their difference is a few hundred roundings of the
largest term at most, so 1e-12 relative to the matrix's largest entry (plus 1e-12 absolute for
zero entries) separates rounding from any modelling error (a planted 10 % is 1e-1).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import sympy as sp

from tests.conformance.closed_forms import closed_forms, model_forms
from tests.conformance.formats import Plant
from tests.conformance.systems import SEED, SYSTEMS, mjcf, parameters, urdf

pytestmark = pytest.mark.conformance
RTOL = 1e-12
STATES = 4


def _numeric(forms, name: str, values: dict[str, float]):
    """(M(q), C(q,q̇) q̇ + H(q)) as NumPy functions of (q, q̇) with the system's numbers."""
    subs = {sp.Symbol(k): v for k, v in values.items()}
    M = sp.lambdify([forms.q], forms.M.subs(subs), "numpy")
    bias = sp.lambdify([forms.q, forms.dq], (forms.C * sp.Matrix(forms.dq) + forms.H).subs(subs), "numpy")
    return (lambda q: np.array(M(q), dtype=float)), (lambda q, v: np.array(bias(q, v), dtype=float).ravel())


def _pinocchio_q(model: pin.Model, angles: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration of joint coordinates (a continuous joint is (cos, sin))."""
    q = []
    for joint, a in zip(list(model.joints)[1:], angles, strict=True):
        q += [np.cos(a), np.sin(a)] if joint.nq == 2 else [a]
    return np.array(q)


def _close(a, b, what):
    scale = max(np.max(np.abs(b)), 1.0)
    assert np.allclose(a, b, rtol=0, atol=RTOL * scale), f"{what}: {a} vs {b}"


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_kane_forcing_splits_into_christoffel_c_and_gravity(name):
    """forcing = B u − C q̇ − H − D q̇ with C from M alone (Christoffel) and H = ∂V/∂q."""
    forms = closed_forms(name)
    rng = np.random.default_rng(SEED)
    symbols = sorted(forms.forcing.free_symbols | forms.C.free_symbols, key=str)
    for _ in range(STATES):
        values = {s: rng.uniform(-2, 2) for s in symbols}
        residual = np.array(forms.forcing_residual().subs(values), dtype=float)
        scale = max(np.max(np.abs(np.array(forms.forcing.subs(values), dtype=float))), 1.0)
        assert np.max(np.abs(residual)) <= RTOL * scale, (name, residual)


@pytest.mark.parametrize("name", ["acrobot", *[n for n in SYSTEMS if n != "acrobot"]])
def test_closed_forms_equal_pinocchio_on_the_written_urdf(name):
    """M = CRBA and C q̇ + H = RNEA(q, q̇, 0) on the generated URDF (the double pendulum first)."""
    values = parameters()[name]
    model = pin.buildModelFromXML(urdf(SYSTEMS[name]))
    data = model.createData()
    M, bias = _numeric(closed_forms(name), name, values)
    rng = np.random.default_rng(SEED)
    for _ in range(STATES):
        q, v = rng.uniform(-np.pi, np.pi, model.nv), rng.uniform(-2, 2, model.nv)
        qp = _pinocchio_q(model, q)
        crba = pin.crba(model, data, qp)
        crba = np.triu(crba) + np.triu(crba, 1).T
        _close(M(q), crba, f"{name} M at q={q}")
        _close(bias(q, v), pin.rnea(model, data, qp, v, np.zeros(model.nv)), f"{name} C q̇ + H at q={q}")


@pytest.mark.parametrize("name", [n for n, s in SYSTEMS.items() if s.mjcf])
def test_closed_forms_with_armature_equal_mujoco_on_the_written_mjcf(name):
    """M (+ armature) = ``mj_fullM`` and C q̇ + H = ``qfrc_bias`` on the generated MJCF."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_string(mjcf(SYSTEMS[name]))
    data = mujoco.MjData(model)
    M, bias = _numeric(model_forms(name, "mjcf"), name, parameters()[name])
    rng = np.random.default_rng(SEED)
    for _ in range(STATES):
        q, v = rng.uniform(-np.pi, np.pi, model.nv), rng.uniform(-2, 2, model.nv)
        data.qpos[:], data.qvel[:] = q, v
        mujoco.mj_forward(model, data)
        full = np.zeros((model.nv, model.nv))
        if hasattr(data, "qM"):  # MuJoCo 3.x takes the sparse qM, MuJoCo 4 the data
            mujoco.mj_fullM(model, full, data.qM)
        else:
            mujoco.mj_fullM(model, data, full)
        # MuJoCo's axial rod moment (systems.AXIAL_INERTIA, 1e-6) enters no planar M: same bound
        _close(M(q), full, f"{name} M at q={q}")
        _close(bias(q, v), data.qfrc_bias, f"{name} C q̇ + H at q={q}")


def test_a_planted_entry_is_caught_by_the_generator_check():
    """The comparison above fails on a planted 10 % (it can fail)."""
    name = "acrobot"
    forms = Plant("M", 0, 1).apply(closed_forms(name))
    model = pin.buildModelFromXML(urdf(SYSTEMS[name]))
    M, _ = _numeric(forms, name, parameters()[name])
    q = np.array([0.3, -0.7])
    with pytest.raises(AssertionError):
        _close(M(q), pin.crba(model, model.createData(), _pinocchio_q(model, q)), "planted")


def test_pickles_are_read_only_from_a_private_folder(tmp_path, monkeypatch):
    """A folder others can write (a planted pickle would run its code when loaded) is not used."""
    import tempfile

    from tests.conformance import closed_forms as module

    monkeypatch.setattr(tempfile, "gettempdir", lambda: str(tmp_path))
    folder = module._private_folder()
    assert folder is not None and (folder.stat().st_mode & 0o777) == 0o700
    folder.chmod(0o777)
    assert module._private_folder() is None
