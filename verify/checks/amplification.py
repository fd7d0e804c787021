"""The term amplification A ≥ 1 of the trust rule, at one state or at a batch of states.

Pinocchio's recursions work with spatial inertias expressed in the world frame, whose
entries grow like m·|c|² (c a centre of mass seen from the world origin); their rounding
is ε times *those* terms.  With W_j = Σ_{k in subtree(j)} m_k|c_k|² + tr I_k for a
revolute joint (M_q,jj for a prismatic one, never less than M_q,jj) and T the coordinate
map, A = max_i (Σ_k |T|_ki √W_k)² / S_i (the argument is in ``pendverify.checks.trust``).

``amplification`` is the one arithmetic: elementwise numpy over optional leading batch
axes, every sum written out in a fixed order, so that one state (``term_amplification``,
cached on the system) and a batch (``term_amplification_batch``, the batched checks)
give the same bits.
"""

from __future__ import annotations

import math

import numpy as np

AMPLIFICATION_CACHE = 4096  # states whose term amplification a system remembers


def joint_levers(system) -> tuple:
    """((v, ((body, mass, lever, tr I), …)), …) for each non-prismatic joint; kept on the system."""
    pm = system.model
    cached = system.__dict__.get("_joint_levers")
    if cached is not None and cached[0] is pm:
        return cached[1]
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
    system.__dict__["_joint_levers"] = (pm, tuple(table))
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


def term_amplification(model, system, q) -> float:
    """A ≥ 1: how much larger than the result (in the model's scaled coordinates) Pinocchio's terms are.

    The trust guard and two checks ask for it at every state: answers are kept on the
    system, keyed by the state, with the model and Pinocchio data they came from (held,
    so that their ids cannot be reused while the entry lives).
    """
    key = np.asarray(q, dtype=float).tobytes()
    cache = system.__dict__.setdefault("_amplification_cache", {})
    entry = cache.get(key)
    if entry is None or entry[0] is not model or entry[1] is not system.data:
        if len(cache) >= AMPLIFICATION_CACHE:
            cache.clear()
        entry = cache[key] = (model, system.data, _term_amplification(model, system, q))
    return entry[2]


def _term_amplification(model, system, q) -> float:
    import pinocchio as pin

    pm, data = system.model, system.data
    config = system.cmap.configuration(q)
    levers = joint_levers(system)
    pin.forwardKinematics(pm, data, config)
    frames = {k: data.oMi[k].homogeneous for k in _bodies(levers)}
    upper = pin.crba(pm, data, config)
    S = model.diagonal_scale(np.asarray(q, dtype=float))
    A = float(amplification(np.diag(upper), frames, levers, np.abs(system.cmap.T), S))
    return A if math.isfinite(A) else math.inf


def term_amplification_batch(model, system, configs: np.ndarray, diag_M: np.ndarray, S: np.ndarray):
    """A at each of a batch of Pinocchio configurations (N, nq), given diag M_q (N, n) and S (N, n)."""
    import pinocchio as pin

    pm, data = system.model, system.data
    levers = joint_levers(system)
    bodies = _bodies(levers)
    frames = {k: np.empty((len(configs), 4, 4)) for k in bodies}
    oMi = data.oMi
    for i, config in enumerate(configs):
        pin.forwardKinematics(pm, data, config)
        for k in bodies:
            frames[k][i] = oMi[k].homogeneous
    return amplification(diag_M, frames, levers, np.abs(system.cmap.T), S)
