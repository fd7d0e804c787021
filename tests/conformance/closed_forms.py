"""Each system's closed forms M, C, H, V, D, B as SymPy expressions, derived independently of pendverify.

``derivation.mass_matrix_and_forcing`` gives M(q) and the forcing of M q̈ = forcing by Kane's
method; from them, in pendverify's convention M q̈ + C q̇ + H + D q̇ = B u (docs/models.md):

* C is built from M alone, by the Christoffel symbols of the first kind,
  C_ij = Σ_k ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i) q̇_k (so Ṁ − 2C is skew);
* V = Σ m g z (``derivation.potential_energy``) and H = ∂V/∂q;
* D = −∂forcing/∂q̇ at q̇ = 0 restricted to the dampers' linear part, B = ∂forcing/∂τ.

``forcing_residual`` is forcing − (B u − C q̇ − H − D q̇), zero when the split is right (a test
evaluates it at seeded numbers: the Christoffel C and the Kane forcing are independent routes).

Symbols are plain: q1…qn, their rates dq1…dqn, the parameters by name, inputs tau1….  Entries
are rewritten by ``_tidy`` so that the files written from them stay short.  ``closed_forms(name)`` is cached
in-process and on disk (a pickle keyed by the digest of this module, ``derivation.py`` and
``systems.py``, in a folder private to the user: ``_private_folder``) so the derivation runs once
per session, and once per edit across sessions.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import os
import pickle
import stat
import tempfile
from pathlib import Path

import sympy as sp
from sympy.physics.mechanics import dynamicsymbols
from sympy.simplify.fu import TR8

from tests.conformance import derivation
from tests.conformance.systems import SYSTEMS

HERE = Path(__file__).resolve().parent


@dataclasses.dataclass(frozen=True)
class ClosedForms:
    """A system's M, C, H, V, D, B (SymPy, plain symbols) and the Kane forcing they split."""

    q: tuple[sp.Symbol, ...]
    dq: tuple[sp.Symbol, ...]
    inputs: tuple[sp.Symbol, ...]
    M: sp.Matrix
    C: sp.Matrix
    H: sp.Matrix
    V: sp.Expr
    D: sp.Matrix
    B: sp.Matrix
    forcing: sp.Matrix

    def forcing_residual(self) -> sp.Matrix:
        u = sp.Matrix(self.inputs) if self.inputs else sp.zeros(0, 1)
        dq = sp.Matrix(self.dq)
        return self.forcing - (self.B * u - self.C * dq - self.H - self.D * dq)


def christoffel(M: sp.Matrix, q, dq) -> sp.Matrix:
    """C(q, q̇) of M by the Christoffel symbols of the first kind (module docstring)."""
    n = M.shape[0]
    dM = [M.diff(qk) for qk in q]
    C = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            C[i, j] = sp.expand(
                sum(sp.Rational(1, 2) * (dM[k][i, j] + dM[j][i, k] - dM[i][j, k]) * dq[k] for k in range(n))
            )
    return C


def _tidy(e: sp.Expr) -> sp.Expr:
    """Products of sines and cosines as sums of cosines of sums (TR8), expanded: short and canonical."""
    return sp.expand(TR8(sp.expand(e)))


def _derive(name: str) -> ClosedForms:
    system = SYSTEMS[name]
    chain = system.chain()
    n = system.dof
    qt = dynamicsymbols(" ".join(f"q{i + 1}" for i in range(n)), seq=True)
    q = sp.symbols([f"q{i + 1}" for i in range(n)])
    dq = sp.symbols([f"dq{i + 1}" for i in range(n)])
    plain = {**{qi.diff(): d for qi, d in zip(qt, dq, strict=True)}, **dict(zip(qt, q, strict=True))}
    mass, forcing = derivation.mass_matrix_and_forcing(chain)
    M = mass.subs(plain).applyfunc(_tidy)
    forcing = forcing.subs(plain)
    V = _tidy(derivation.potential_energy(chain).subs(plain))
    H = sp.Matrix([sp.expand(V.diff(qi)) for qi in q])
    inputs = sp.symbols(list(system.inputs)) if system.inputs else ()
    B = forcing.jacobian(sp.Matrix(inputs)) if inputs else sp.zeros(n, 0)
    damping = [sp.Symbol(j["damping"]) if j["damping"] else 0 for j in chain]
    D = sp.diag(*damping)
    C = christoffel(M, q, dq)
    return ClosedForms(tuple(q), tuple(dq), tuple(inputs), M, C, H, V, D, sp.Matrix(B), forcing)


def _digest() -> str:
    h = hashlib.sha256()
    for module in ("closed_forms.py", "derivation.py", "systems.py"):
        h.update((HERE / module).read_bytes())
    h.update(sp.__version__.encode())
    return h.hexdigest()[:16]


def _private_folder() -> Path | None:
    """The folder of the pickles: ``pendverify-conformance-<uid>`` in the temporary folder, mode
    0700.  A pickle runs code when loaded, so one is read only from a folder this user owns and
    nobody else can write (else None: derive without a cache); the shared temporary folder
    itself is writable by every user."""
    uid = os.getuid()
    folder = Path(tempfile.gettempdir()) / f"pendverify-conformance-{uid}"
    try:
        folder.mkdir(mode=0o700, exist_ok=True)
        info = folder.lstat()
    except OSError:
        return None
    private = stat.S_ISDIR(info.st_mode) and info.st_uid == uid and not info.st_mode & 0o077
    return folder if private else None


@functools.cache
def closed_forms(name: str) -> ClosedForms:
    """The closed forms of system ``name``, derived once (module docstring).  Written atomically
    (a temporary file renamed into place), so xdist workers deriving the same system at once
    each read a whole pickle or none."""
    folder = _private_folder()
    if folder is None:
        return _derive(name)
    path = folder / f"{_digest()}-{name}.pickle"
    if path.is_file():
        try:
            return pickle.loads(path.read_bytes())
        except Exception:  # a torn or stale pickle: derive again
            pass
    forms = _derive(name)
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=path.name, suffix=".tmp")
    with os.fdopen(fd, "wb") as f:
        f.write(pickle.dumps(forms))
    os.replace(tmp, path)
    return forms


def model_forms(name: str, description: str) -> ClosedForms:
    """The closed forms a model of system ``name`` checked against ``description`` writes: the
    derivation's, with the joints' armature added to M's diagonal where the description has it
    (MJCF ``armature``; a URDF has none)."""
    forms = closed_forms(name)
    armatures = SYSTEMS[name].armatures(description)
    if not armatures:
        return forms
    return dataclasses.replace(forms, M=forms.M + sp.diag(*sp.symbols(list(armatures))))
