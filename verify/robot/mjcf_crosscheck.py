"""MuJoCo and the Pinocchio model built from it, compared before any verdict.

On ``STATES`` states drawn with the fixed seed ``SEED`` (q uniform in [−π, π], v uniform in
[−2, 2] per coordinate; a slide's q in [−1, 1] m), ``cross_check`` compares

* MuJoCo's M (``mj_fullM`` after ``mj_forward``) with Pinocchio's ``crba`` (symmetrised; both
  hold ``dof_armature`` on the diagonal), and
* MuJoCo's ``qfrc_bias`` (C(q, v)·v + H(q) with the file's gravity; no passive forces, so no
  damping) with Pinocchio's ``rnea(q, v, 0)``.

Tolerance.  Both engines compute the same sums of products in double precision by different
recursions; each entry of M is Σ over the n_b bodies below both joints of terms built from a
few dozen roundings each, so the two differ by at most about K·ε·n_b times the size of those
terms.  For a positive definite M, |M_ij| ≤ √(M_ii M_jj) and each diagonal entry is a sum of
non-negative terms, so √(M_ii M_jj) bounds the size of the terms of M_ij:
    |ΔM_ij| ≤ K ε n_b √(M_ii M_jj).
For the bias, H_i = −Σ_b m_b J_b,iᵀγ is bounded, by Cauchy–Schwarz over the bodies, by
|γ| √(m_tot M_ii) (a hinge: Σ m_b r_b ≤ √(Σ m_b) √(Σ m_b r_b²); a slide: m_sub ≤ √(m_tot M_ii)),
and C(q, v)·v by the size of M's rate of change, n ‖M‖_max ‖v‖²_∞, so
    |Δbias_i| ≤ K ε n_b (|γ| √(m_tot M_ii) + n ‖M‖_max ‖v‖²_∞).
K = ``ROUNDING_FACTOR`` = 64 covers the roundings of both recursions (each a few tens per body)
with room, and still lies ten orders of magnitude below a 1 % error in a mass or a length.
A disagreement beyond it means the model Pinocchio was given is not the one MuJoCo compiled:
the file is refused with the largest difference, before any check runs.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin

from pendverify.errors import UrdfShapeError
from pendverify.robot.mjcf_pinocchio import SLIDE, pinocchio_configuration

#: the seed of the cross-check's states (fixed: the same file is always compared at the same states)
SEED = 25
#: how many states are compared
STATES = 5
#: K of the tolerance K·ε·n_b·(size of the terms); see the module docstring
ROUNDING_FACTOR = 64
EPS = np.finfo(float).eps


def cross_check(mj: mujoco.MjModel, model: pin.Model, joints: list[int], source: str) -> None:
    """Refuse ``source`` when MuJoCo's and Pinocchio's M or bias differ beyond the rounding bound."""
    if model.nv == 0:
        return
    data, mjd = model.createData(), mujoco.MjData(mj)
    rng = np.random.default_rng(SEED)
    dofs = [int(mj.jnt_dofadr[j]) for j in joints]
    slides = np.array([mj.jnt_type[j] == SLIDE for j in joints])
    m_total = float(sum(model.inertias[j].mass for j in range(1, model.njoints)))
    n_bodies = max(1, mj.nbody - 1)
    gravity = float(np.linalg.norm(mj.opt.gravity))
    for _ in range(STATES):
        q = np.where(slides, rng.uniform(-1.0, 1.0, model.nv), rng.uniform(-np.pi, np.pi, model.nv))
        v = rng.uniform(-2.0, 2.0, model.nv)
        mjd.qpos[:] = pinocchio_configuration(mj, joints, q)
        mjd.qvel[:] = 0.0
        mjd.qvel[dofs] = v
        mujoco.mj_forward(mj, mjd)
        full = mass_matrix(mj, mjd)
        M_mj, bias_mj = full[np.ix_(dofs, dofs)], np.array(mjd.qfrc_bias)[dofs]
        M_pin = pin.crba(model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T
        bias_pin = pin.rnea(model, data, q, v, np.zeros(model.nv))
        diag = np.abs(np.diag(M_mj))
        k = ROUNDING_FACTOR * EPS * n_bodies
        tol_M = k * np.sqrt(np.outer(diag, diag))
        tol_bias = k * (gravity * np.sqrt(m_total * diag) + model.nv * np.max(np.abs(M_mj)) * np.max(v**2))
        _compare("M", M_pin, M_mj, tol_M, q, source)
        _compare("the bias forces", bias_pin, bias_mj, tol_bias, q, source)


def mass_matrix(mj: mujoco.MjModel, mjd: mujoco.MjData) -> np.ndarray:
    """MuJoCo's dense M at ``mjd``'s state (``mj_fullM``: MuJoCo 4 takes the data, 3.x its ``qM``)."""
    full = np.zeros((mj.nv, mj.nv))
    if hasattr(mjd, "qM"):
        mujoco.mj_fullM(mj, full, mjd.qM)
    else:
        mujoco.mj_fullM(mj, mjd, full)
    return full


def _compare(what: str, pinocchio, mujoco_value, tol, q, source: str) -> None:
    diff = np.abs(pinocchio - mujoco_value)
    if not np.all(diff <= tol):
        worst = np.unravel_index(int(np.argmax(diff - tol)), diff.shape)
        entry = ",".join(str(int(i) + 1) for i in worst)
        raise UrdfShapeError(
            source,
            f"Pinocchio's model of the compiled MJCF disagrees with MuJoCo's {what} at q = "
            f"{np.round(q, 6).tolist()}: entry ({entry}) is {pinocchio[worst]:.12g} in Pinocchio and "
            f"{mujoco_value[worst]:.12g} in MuJoCo (difference {diff[worst]:.3g}, rounding allows "
            f"{tol[worst]:.3g}); refused",
        )
