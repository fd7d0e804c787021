"""A planar chain of n equal links, as a URDF and as a Python-class model of any size (test support).

Link k (1-based) turns about x at joint k, relative to link k − 1; the links lie along y at zero,
z is up (gravity −z).  With absolute angles φ_k = q_1 + … + q_k and e(φ) = (cos φ, sin φ) in the
(y, z) plane, link k's centre of mass is

    p_k = Σ_{j<k} l·e(φ_j) + r·e(φ_k),

its Jacobian column for q_i (i ≤ k) is J_k,i = Σ_{i≤j<k} l·e⊥(φ_j) + r·e⊥(φ_k) with
e⊥(φ) = (−sin φ, cos φ), and every joint i ≤ k turns it at rate 1.  Hence

    M_ij = Σ_{k ≥ max(i, j)} (m·J_k,i · J_k,j + I),
    C(q, q̇)·q̇ = Σ_k m·J_kᵀ a_k,   a_k = −Σ_{j<k} l·φ̇_j²·e(φ_j) − r·φ̇_k²·e(φ_k)

(the centre's acceleration at q̈ = 0; the rotation adds none in a plane), H = ∂V/∂q with
V = Σ_k m·g·z_k.  The model writes C·q̇ only (``BiasOnlyModel``).  SymPy can read it (its loops
expand to sums of products of sines and cosines), slowly beyond ten links; ``numeric`` declares
it evaluated numerically only.  ``PLANTED`` names an entry
of M to write wrong; the model class is written as a file, as a user's plug-in is.
"""

from __future__ import annotations

from pathlib import Path

LINK = {"m": 1.0, "l": 0.3, "r": 0.15, "I": 0.0075, "g": 9.81}


def chain_urdf(n: int) -> str:
    """The URDF of an n-link planar chain with ``LINK``'s values."""
    p = LINK
    parts = ['<?xml version="1.0"?>', f'<robot name="chain{n}">', '  <link name="base"/>']
    for k in range(1, n + 1):
        parent = "base" if k == 1 else f"link{k - 1}"
        offset = 0.0 if k == 1 else p["l"]
        parts += [
            f'  <joint name="joint{k}" type="revolute">',
            f'    <parent link="{parent}"/><child link="link{k}"/>',
            f'    <origin xyz="0 {offset!r} 0" rpy="0 0 0"/><axis xyz="1 0 0"/>',
            '    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>',
            "  </joint>",
            f'  <link name="link{k}"><inertial><origin xyz="0 {p["r"]!r} 0" rpy="0 0 0"/>'
            f'<mass value="{p["m"]!r}"/><inertia ixx="{p["I"]!r}" ixy="0" ixz="0" iyy="0" iyz="0" '
            f'izz="{p["I"]!r}"/></inertial></link>',
        ]
    return "\n".join([*parts, "</robot>", ""])


MODEL = '''
import dataclasses

import numpy as np

from pendverify.analytic.interface import BiasOnlyModel
from pendverify.analytic.parameter_set import ParameterSet, quantity

N = {n}
PLANTED = {planted!r}  # (i, j, factor): M[i][j] (0-based) times factor, or None


@dataclasses.dataclass(frozen=True)
class ChainParams(ParameterSet):
    model = "chain{n}"
    m: float = quantity("mass", "mass of each link [kg]")
    l: float = quantity("length", "joint to joint [m]")
    r: float = quantity("offset", "joint to the link's centre of mass [m]")
    I: float = quantity("inertia", "each link about its centre of mass [kg·m²]")
    g: float = quantity("gravity", "gravitational acceleration [m/s²]")


class Chain(BiasOnlyModel):
    name = "chain{n}"
    numeric_only = {numeric_only!r}
    params_type = ChainParams
    coordinates = tuple(f"q{{k + 1}}" for k in range(N))
    angular = (True,) * N
    urdf_joints = tuple(f"joint{{k + 1}}" for k in range(N))

    def _angles(self, q):
        phi, total = [], 0
        for k in range(N):
            total = total + q[k]
            phi.append(total)
        return phi

    def _jacobian(self, phi, k):
        """Columns i ≤ k of link k's centre-of-mass Jacobian, as (y, z) pairs."""
        p, cos, sin = self.params, self.math.cos, self.math.sin
        columns, ty, tz = [], -p.r * sin(phi[k]), p.r * cos(phi[k])
        for i in range(k, -1, -1):
            columns.append((ty, tz))
            if i > 0:
                ty, tz = ty - p.l * sin(phi[i - 1]), tz + p.l * cos(phi[i - 1])
        return columns[::-1]

    def mass_matrix(self, q):
        p, phi = self.params, self._angles(q)
        M = [[0] * N for _ in range(N)]
        for k in range(N):
            J = self._jacobian(phi, k)
            for i in range(k + 1):
                for j in range(k + 1):
                    M[i][j] = M[i][j] + p.m * (J[i][0] * J[j][0] + J[i][1] * J[j][1]) + p.I
        if PLANTED is not None:
            i, j, factor = PLANTED
            M[i][j] = factor * M[i][j]
        return np.array(M)

    def coriolis_force(self, q, v):
        p, phi, cos, sin = self.params, self._angles(q), self.math.cos, self.math.sin
        rates, total = [], 0
        for k in range(N):
            total = total + v[k]
            rates.append(total)
        out = [0] * N
        for k in range(N):
            ay = -p.r * rates[k] ** 2 * cos(phi[k])
            az = -p.r * rates[k] ** 2 * sin(phi[k])
            for j in range(k):
                ay, az = ay - p.l * rates[j] ** 2 * cos(phi[j]), az - p.l * rates[j] ** 2 * sin(phi[j])
            for i, (jy, jz) in enumerate(self._jacobian(phi, k)):
                out[i] = out[i] + p.m * (jy * ay + jz * az)
        return np.array(out)

    def gravity(self, q):
        p, phi = self.params, self._angles(q)
        out = [0] * N
        for k in range(N):
            for i, (_, jz) in enumerate(self._jacobian(phi, k)):
                out[i] = out[i] + p.m * p.g * jz
        return np.array(out)

    def gravity_scale(self):
        """|H_i| ≤ Σ_{{k ≥ i}} m·g·((k − i)·l + r): each lever arm at its longest."""
        p = self.params
        return np.array([sum(p.m * p.g * ((k - i) * p.l + p.r) for k in range(i, N)) for i in range(N)])

    def diagonal_scale(self, q):
        """M_ii ≤ Σ_{{k ≥ i}} (m·((k − i)·l + r)² + I): each |J_k,i| at its longest."""
        p = self.params
        return np.array([sum(p.m * ((k - i) * p.l + p.r) ** 2 + p.I for k in range(i, N)) for i in range(N)])

    def potential_energy(self, q):
        p, phi, sin = self.params, self._angles(q), self.math.sin
        height, V = 0, 0
        for k in range(N):
            V = V + p.m * p.g * (height + p.r * sin(phi[k]))
            height = height + p.l * sin(phi[k])
        return V
'''


def write_chain(folder: Path, n: int, planted=None, numeric: bool = False) -> tuple[str, str, str]:
    """(model file, URDF, parameter file) of an n-link chain in ``folder``; ``planted`` = (i, j, factor)
    writes M[i][j] (0-based) times factor; ``numeric``: the model is evaluated numerically only
    (``ClosedFormModel.numeric_only``: SymPy does not expand its loops, which takes minutes beyond
    ten links)."""
    folder.mkdir(parents=True, exist_ok=True)
    model = folder / f"chain{n}.py"
    why = "its sums over the links are evaluated numerically" if numeric else ""
    model.write_text(MODEL.format(n=n, planted=planted, numeric_only=why))
    urdf = folder / f"chain{n}.urdf"
    urdf.write_text(chain_urdf(n))
    params = folder / f"chain{n}.toml"
    values = "\n".join(f"{k} = {v!r}" for k, v in LINK.items())
    params.write_text(f'model = "chain{n}"\n\n[parameters]\n{values}\n')
    return str(model), str(urdf), str(params)
