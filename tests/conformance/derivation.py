"""Equations of motion of a serial chain by Kane's method (``sympy.physics.mechanics``).

This module is self-contained (it imports SymPy only): the conformance tests derive every
system's closed forms with it, and the mechanics model files they write embed its text
verbatim with a ``CHAIN`` literal, so the file pendverify reads holds the derivation itself.

The chain (the geometry the robot-description writers of ``tests/conformance/systems.py``
use, so the derivation and the URDF cannot drift apart):

* the world N: z up, gravity ``−g`` along N.z; every frame equals N at q = 0;
* joint i sits at ``origin`` (x, y, z; SymPy strings in the parameters) in the frame of link
  i − 1 (N for the first joint) and moves along or about ``axis`` ("x", "y" or "z" of the
  parent frame, equal to the link's at the joint): a ``revolute`` joint turns link i by q_i
  about it, a ``prismatic`` one slides link i by q_i along it;
* link i has its centre of mass at ``com`` in its own frame, mass ``mass`` and, unless
  ``inertia`` is None (a point mass), the principal moments (Ixx, Iyy, Izz) about its centre
  of mass in its own frame;
* ``damping`` (a parameter name or None) is a viscous force or torque −b q̇_i at the joint,
  acting on link i and reacting on its parent; ``actuated`` joints take an input ``tau<k>``
  (k counts the actuated joints) as force or torque between parent and link.

``kane(chain)`` returns the ``KanesMethod`` after ``kanes_equations`` with the speeds
u_i = q̇_i (``kd_eqs`` q̇_i − u_i), the equations M(q) u̇ = forcing(q, u, τ).  Armature is
not a body property: ``mass_matrix`` adds it to M's diagonal (as MuJoCo and Pinocchio do).
"""

from __future__ import annotations

import sympy as sp
from sympy.physics.mechanics import (
    KanesMethod,
    Particle,
    Point,
    ReferenceFrame,
    RigidBody,
    dynamicsymbols,
    inertia,
)


def _vector(frame, xyz):
    return sum((sp.sympify(c) * getattr(frame, a) for c, a in zip(xyz, "xyz", strict=True)), 0 * frame.x)


def _build(chain):
    """(world N, its origin O, q, u, bodies, loads) of ``chain``."""
    n = len(chain)
    q = dynamicsymbols(" ".join(f"q{i + 1}" for i in range(n)), seq=True)
    u = dynamicsymbols(" ".join(f"u{i + 1}" for i in range(n)), seq=True)
    g = sp.Symbol("g")
    world = ReferenceFrame("N")
    origin = Point("O")
    origin.set_vel(world, 0)
    parent_frame, parent_point = world, origin
    bodies, loads, k = [], [], 0
    for i, joint in enumerate(chain):
        axis = getattr(parent_frame, joint["axis"])
        joint_point = parent_point.locatenew(f"J{i + 1}", _vector(parent_frame, joint["origin"]))
        if joint["type"] == "revolute":
            frame = parent_frame.orientnew(f"F{i + 1}", "Axis", (q[i], axis))
            frame.set_ang_vel(parent_frame, u[i] * axis)
            link_point = joint_point
            joint_point.v2pt_theory(parent_point, world, parent_frame)
        else:
            frame = parent_frame.orientnew(f"F{i + 1}", "Axis", (0, axis))
            frame.set_ang_vel(parent_frame, 0)
            joint_point.v2pt_theory(parent_point, world, parent_frame)
            link_point = joint_point.locatenew(f"S{i + 1}", q[i] * axis)
            link_point.set_vel(
                world,
                joint_point.vel(world) + u[i] * axis + parent_frame.ang_vel_in(world).cross(q[i] * axis),
            )
        com = link_point.locatenew(f"G{i + 1}", _vector(frame, joint["com"]))
        com.v2pt_theory(link_point, world, frame)
        mass = sp.Symbol(joint["mass"])
        if joint["inertia"] is None:
            body = Particle(f"B{i + 1}", com, mass)
        else:
            moments = [sp.sympify(c) for c in joint["inertia"]]
            body = RigidBody(f"B{i + 1}", com, frame, mass, (inertia(frame, *moments), com))
        bodies.append(body)
        loads.append((com, -mass * g * world.z))
        generalised = 0
        if joint.get("damping"):
            generalised -= sp.Symbol(joint["damping"]) * u[i]
        if joint.get("actuated"):
            k += 1
            generalised += sp.Symbol(f"tau{k}")
        if generalised != 0:
            if joint["type"] == "revolute":
                loads += [(frame, generalised * axis), (parent_frame, -generalised * axis)]
            else:
                loads += [(link_point, generalised * axis), (joint_point, -generalised * axis)]
        parent_frame, parent_point = frame, link_point
    return world, origin, q, u, bodies, loads


def kane(chain):
    """The ``KanesMethod`` of ``chain`` (a list of joint dicts, module docstring), equations formed."""
    world, _, q, u, bodies, loads = _build(chain)
    method = KanesMethod(
        world, q_ind=q, u_ind=u, kd_eqs=[qi.diff() - ui for qi, ui in zip(q, u, strict=True)]
    )
    method.kanes_equations(bodies, loads)
    return method


def potential_energy(chain):
    """V(q) = Σ m_i g z_i, z_i the height of link i's centre of mass above O."""
    world, origin, _, _, bodies, _ = _build(chain)
    return sum(b.mass * sp.Symbol("g") * b.masscenter.pos_from(origin).dot(world.z) for b in bodies)


def armature(chain):
    """The diagonal matrix of the joints' armatures (zero where a joint has none)."""
    return sp.diag(*[sp.Symbol(j["armature"]) if j.get("armature") else 0 for j in chain])


def mass_matrix_and_forcing(chain):
    """(M, forcing) of M q̈ = forcing in q, q̇ (dynamic symbols q_i and their derivatives), armature in M."""
    method = kane(chain)
    n = len(chain)
    q = dynamicsymbols(" ".join(f"q{i + 1}" for i in range(n)), seq=True)
    u = dynamicsymbols(" ".join(f"u{i + 1}" for i in range(n)), seq=True)
    speeds = {ui: qi.diff() for ui, qi in zip(u, q, strict=True)}
    mass = method.mass_matrix.subs(speeds) + armature(chain)
    return mass, method.forcing.subs(speeds)
