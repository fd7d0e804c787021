"""The term amplification A ≥ 1 of the trust rule, at each state of a batch.

Pinocchio's recursions work with spatial inertias expressed in the world frame, whose
entries grow like m·|c|² (c a centre of mass seen from the world origin); their rounding
is ε times *those* terms.  With W_j = Σ_{k in subtree(j)} m_k|c_k|² + tr I_k for a
revolute joint (M_q,jj for a prismatic one, never less than M_q,jj) and T the coordinate
map, A = max_i (Σ_k |T|_ki √W_k)² / S_i (the argument is in ``pendverify.checks.trust``).

``amplification`` is the arithmetic, elementwise over leading batch axes;
``term_amplification_batch`` feeds it the placements of a batch of configurations.
"""

from __future__ import annotations

import numpy as np


def joint_levers(pm) -> tuple:
    """((v, ((body, mass, lever, tr I), …)), …) for each non-prismatic joint of Pinocchio model ``pm``."""
    table = []
    for j in range(1, pm.njoints):
        name = pm.joints[j].shortname()
        if "Prismatic" in name or name.startswith("JointModelP"):
            continue
        bodies = tuple(
            (
                k,
                float(pm.inertias[k].mass),
                tuple(float(x) for x in pm.inertias[k].lever),
                float(np.trace(pm.inertias[k].inertia)),
            )
            for k in pm.subtrees[j]
        )
        table.append((pm.joints[j].idx_v, bodies))
    return tuple(table)


def _bodies(levers) -> list[int]:
    return sorted({k for _, bodies in levers for k, *_ in bodies})


def amplification(diag_M, frames: dict, levers, abs_T: np.ndarray, S):
    """A from Pinocchio's diag M_q, the bodies' placements {body: oMi homogeneous} and S.

    Arrays may carry leading batch axes (then ``frames[k]`` is (…, 4, 4)); the result
    has those axes.  c_k = R_k·lever_k + p_k, |c_k|² and the sums over k are written out.
    """
    W = np.abs(np.asarray(diag_M, dtype=float)).copy()
    for v, bodies in levers:
        world = 0.0
        for k, mass, (l0, l1, l2), trace in bodies:
            H = frames[k]
            c = [H[..., i, 0] * l0 + H[..., i, 1] * l1 + H[..., i, 2] * l2 + H[..., i, 3] for i in range(3)]
            world = world + (mass * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) + trace)
        W[..., v] = np.where(world > W[..., v], world, W[..., v])
    root = np.sqrt(W)
    n = W.shape[-1]
    diag_E = []
    for i in range(n):
        u = abs_T[0, i] * root[..., 0]
        for k in range(1, n):
            u = u + abs_T[k, i] * root[..., k]
        diag_E.append(u * u)
    with np.errstate(all="ignore"):
        A = np.max(np.stack(diag_E, axis=-1) / S, axis=-1)
        return np.where(np.isfinite(A), np.where(1.0 > A, 1.0, A), np.inf)


def term_amplification_batch(system, configs: np.ndarray, diag_M: np.ndarray, S: np.ndarray):
    """A at each of a batch of Pinocchio configurations (N, nq), given diag M_q (N, n) and S (N, n)."""
    import pinocchio as pin

    pm, data = system.model, system.data
    levers = joint_levers(pm)
    bodies = _bodies(levers)
    frames = {k: np.empty((len(configs), 4, 4)) for k in bodies}
    oMi = data.oMi
    for i, config in enumerate(configs):
        pin.forwardKinematics(pm, data, config)
        for k in bodies:
            frames[k][i] = oMi[k].homogeneous
    return amplification(diag_M, frames, levers, np.abs(system.cmap.T), S)
