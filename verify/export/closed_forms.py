"""The quantities a model writes, as SymPy matrices over its own names: what ``export`` writes.

A model's M(q), C(q, q̇)·q̇, G(q), and its D, B and W (where it has inputs and disturbances), read
by ``SymbolicModel`` as ``show`` reads them; and det M(q) and q̈(q, q̇, u, w) where the model
writes its own closed forms of them (the reference systems' det M and f + g·u, a text model's
``det_M`` and ``qddot``).  A derived det M or q̈ is not written: it would be a composition of the
other functions, which code that needs it composes.  A model of q̈ alone (no M) writes q̈, D, B
and W.  Each is a matrix (a vector is one column; det M is 1 × 1) over the coordinates, their
rates ``d<coordinate>``, the inputs, the disturbances and the parameters, named as the model
names them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from pendverify.analytic.numpy_model import FUNCTIONS
from pendverify.analytic.source_file import where
from pendverify.errors import PendverifyError

#: what each exported quantity is, by its function's name in the NumPy-functions model format
#: (``pendverify.analytic.numpy_model.FUNCTIONS``), in the order files list them
DESCRIPTIONS = {
    "M": "the mass matrix M(q), n × n",
    "Cqdot": "the Coriolis and centrifugal force C(q, q̇)·q̇, n entries",
    "G": "the gravity vector G(q) = ∂V/∂q, n entries",
    "D": "the viscous friction matrix D, n × n",
    "B": "the input matrix B, n × inputs",
    "W": "the disturbance matrix W, n × disturbances",
    "det_M": "the determinant det M(q), a number",
    "qddot": "the accelerations q̈(q, q̇, u, w), n entries",
}
#: the quantities written only where the model writes them itself: key → the model's method
OWN_ONLY = {"det_M": "det_mass_matrix", "qddot": "acceleration"}
#: the quantities of a model of q̈ alone
ACCELERATION_ONLY = ("qddot", "D", "B", "W")
#: key → (the model's method, its arguments, what it is)
QUANTITIES = {key: (FUNCTIONS[key][2], FUNCTIONS[key][0], what) for key, what in DESCRIPTIONS.items()}


@dataclass(frozen=True)
class ExportForms:
    """A model's quantities (``QUANTITIES``) and what a declaration of them says."""

    name: str
    source: Path | None
    coordinates: tuple[str, ...]
    angular: tuple[bool, ...]
    inputs: tuple[str, ...]
    disturbances: tuple[str, ...]
    parameters: tuple[tuple[str, str, str], ...]  # (name, kind, unit)
    urdf: dict
    quantities: dict  # key → sp.Matrix
    q: tuple
    v: tuple
    p: tuple
    u: tuple = ()
    w: tuple = ()
    #: the model's own parameter values (its ``default_params``), {} when it has none
    default_params: dict = dataclasses.field(default_factory=dict)
    #: the files the model file reads (a declaration's .m files)
    companions: tuple[Path, ...] = ()

    @property
    def rates(self) -> tuple[str, ...]:
        return tuple(f"d{c}" for c in self.coordinates)

    def arguments(self, key: str) -> tuple[str, ...]:
        """The arguments before ``p`` of ``key``'s function where an empty one is left out (C,
        MATLAB): of "q", "v", "u", "w", those the quantity depends on by its kind and that have
        entries."""
        sizes = {"q": len(self.q), "v": len(self.v), "u": len(self.u), "w": len(self.w)}
        return tuple(a for a in QUANTITIES[key][1] if sizes[a])

    def shape(self, key: str) -> str:
        """ "matrix", "vector" or "number": how ``key``'s value is returned."""
        shapes = {"nn": "matrix", "nu": "matrix", "nw": "matrix", "n": "vector", "": "number"}
        return shapes[FUNCTIONS[key][1]]

    def declaration(self) -> dict:
        """The model's declaration (``pendverify.analytic.text_parse.DECLARATION_KEYS``)."""
        out = {
            "name": self.name,
            "coordinates": {
                c: "angle" if a else "position" for c, a in zip(self.coordinates, self.angular, strict=True)
            },
            "inputs": list(self.inputs),
            "disturbances": list(self.disturbances),
            "parameters": {n: {"kind": k, "unit": u} for n, k, u in self.parameters},
        }
        if self.urdf:
            out["urdf"] = self.urdf
        return out

    def dynamics_arrays(self) -> dict[str, str]:
        """Where ``DYNAMICS`` code ``qddot(q, v, u, **p)`` finds each argument group: u holds the
        inputs, then the disturbances (``pendverify.analytic.python_dynamics``)."""
        nu = len(self.u)
        return {"q": "q", "v": "v", "u": f"u[:{nu}]", "w": f"u[{nu}:]"}

    def dynamics_declaration(self) -> dict:
        """The declaration of q̈ alone written as ``DYNAMICS`` code: ``declaration()``, the signature
        ``qddot(q, v, u)``, and B, D and W as a text model writes them
        (``pendverify.analytic.python_dynamics``)."""
        out = {**self.declaration(), "dynamics": "qddot(q, v, u)"}
        for key in ("B", "D", "W"):
            if key in self.quantities:
                matrix = self.quantities[key]
                out[key] = [[str(matrix[i, j]) for j in range(matrix.cols)] for i in range(matrix.rows)]
        return out


def export_forms(model_cls) -> ExportForms:
    """The quantities of ``model_cls`` (module docstring); a ``PendverifyError`` naming the model
    when SymPy cannot read them."""
    from pendverify.analytic.parameter_set import KIND_RULES
    from pendverify.analytic.symbolic_reading import SymbolicModel

    sm = SymbolicModel.of(model_cls)
    n = len(model_cls.coordinates)
    names = {
        **{s: sp.Symbol(c, real=True) for s, c in zip(sm.symbols["q"], model_cls.coordinates, strict=True)},
        **{
            s: sp.Symbol(f"d{c}", real=True)
            for s, c in zip(sm.symbols["v"], model_cls.coordinates, strict=True)
        },
        **{s: sp.Symbol(s.name, real=True) for s in (*sm.symbols["u"], *sm.symbols["w"])},
    }
    fields = dataclasses.fields(model_cls.params_type)
    names |= {sm.parameters[f.name]: sp.Symbol(f.name, real=True) for f in fields}
    quantities = {}
    widths = {"B": len(model_cls.inputs), "W": len(getattr(model_cls, "disturbances", ()))}
    written = model_cls.hand_written()
    for key, (method, args, _) in QUANTITIES.items():
        if key in widths and widths[key] == 0:
            continue
        if key in OWN_ONLY and OWN_ONLY[key] not in written:
            continue
        if not model_cls.has_mass_matrix and key not in ACCELERATION_ONLY:
            continue
        value = _evaluate(sm, model_cls, key, method, args)
        matrix = sp.Matrix(value) if isinstance(value, sp.MatrixBase) else sp.Matrix([value])
        if FUNCTIONS[key][1] == "n" and len(matrix) == n:
            matrix = matrix.reshape(n, 1)  # a vector, however the model shaped it
        want = {"n": (n, 1), "": (1, 1)}.get(FUNCTIONS[key][1], (n, widths.get(key, n)))
        if matrix.shape != want:
            raise PendverifyError(
                f"{where(model_cls)}: {method} must be {want[0]} × {want[1]}, got {matrix.shape}"
            )
        quantities[key] = matrix.xreplace(names)
    allowed = set(names.values())
    for key, matrix in quantities.items():
        stray = sorted(s.name for s in matrix.free_symbols - allowed)
        if stray:
            raise PendverifyError(f"{where(model_cls)}: {QUANTITIES[key][0]} depends on {', '.join(stray)}")
    urdf = {}
    if model_cls.urdf_joints:
        urdf["joints"] = list(model_cls.urdf_joints)
    if model_cls.joint_transform is not None:
        urdf["transform"] = [[float(x) for x in row] for row in model_cls.joint_transform]
    if model_cls.joint_offset is not None:
        urdf["offset"] = [float(x) for x in model_cls.joint_offset]
    source = Path(where(model_cls))  # the file, or the module's name for a class made at run time
    return ExportForms(
        name=model_cls.name,
        source=source if source.is_file() else None,
        coordinates=tuple(model_cls.coordinates),
        angular=tuple(bool(a) for a in model_cls.angular),
        inputs=tuple(model_cls.inputs),
        disturbances=tuple(getattr(model_cls, "disturbances", ())),
        parameters=tuple(
            (f.name, f.metadata["kind"], f.metadata.get("unit") or KIND_RULES[f.metadata["kind"]][1])
            for f in fields
        ),
        urdf=urdf,
        quantities=quantities,
        q=tuple(sp.Symbol(c, real=True) for c in model_cls.coordinates),
        v=tuple(sp.Symbol(f"d{c}", real=True) for c in model_cls.coordinates),
        p=tuple(sp.Symbol(f.name, real=True) for f in fields),
        default_params=model_cls.default_params.as_dict() if model_cls.default_params is not None else {},
        u=tuple(sp.Symbol(name, real=True) for name in model_cls.inputs),
        w=tuple(sp.Symbol(name, real=True) for name in getattr(model_cls, "disturbances", ())),
        companions=tuple(
            getattr(getattr(getattr(model_cls, "text_spec", None), "matlab", None), "files", ())
        ),
    )


def _evaluate(sm, model_cls, key: str, method: str, args: str):
    """One quantity: C·q̇ from the model's C(q, q̇) where it writes the matrix, G as ∂V/∂q where
    it writes V alone; every other one as the model's method gives it."""
    written = model_cls.hand_written()
    if key == "Cqdot" and "coriolis_force" not in written:
        if "coriolis_matrix" in written:
            return sp.Matrix(sm.evaluate("coriolis_matrix", "qv")) * sp.Matrix(sm.symbols["v"])
        return sp.Matrix(sm.evaluate("bias", "qv")) - sp.Matrix(_evaluate(sm, model_cls, "G", "gravity", "q"))
    if key == "G" and "gravity" not in written and "potential_energy" in written:
        V = sm.evaluate("potential_energy", "q")
        V = V[0] if isinstance(V, sp.MatrixBase) else V
        return sp.Matrix([sp.diff(V, q) for q in sm.symbols["q"]])
    return sm.evaluate(method, args)
