"""What a closed-form model sees of a URDF: its coordinate map, and what it cannot express.

``UrdfGeometry`` is what a *geometry reader* returns for a model and a URDF
loaded in Pinocchio: the coordinate map q = T (θ − θ0) (``pendverify.robot.coordinates``),
parameters read off the URDF where the model's family fixes them, notes, and a
``ModelForm`` for a term of the URDF the closed form cannot express.

Readers are looked up by the name a model class gives in ``geometry_reader``, never chosen by
a model's name: the reference systems' readers live beside them
(``pendverify.analytic.reference_geometry.READERS``); a model without one declares its map
(``urdf_joints``, ``joint_transform``, ``joint_offset``; ``pendverify.robot.joint_map``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from pendverify.analytic import ParameterSet
from pendverify.robot.coordinates import CoordinateMap

#: Largest relative size (|ΔH_i| / Σ|terms of H_i|) of a term the closed form cannot express
#: for which a URDF still counts as inside the model's family.  1e-4 passes mesh-derived
#: centres of mass rounded at the micrometre (example-robot-data: 7.6e-6) and fails
#: a 0.1 mm offset on a 0.5 m pendulum; ``pendverify check --model-form-rtol`` sets it.
MODEL_FORM_RTOL = 1e-4
DEFAULT_G = 9.81  # m/s², Pinocchio's default, used when a URDF alone is given


@dataclass
class UrdfGeometry:
    """What the URDF's geometry says, in a model's terms."""

    cmap: CoordinateMap
    #: Parameters read off the URDF (double pendulum only; None for the cart).
    params: ParameterSet | None = None
    #: A term of the URDF the closed form cannot express (an off-line centre of
    #: mass); None for URDFs inside the family.
    model_form: ModelForm | None = None
    notes: list[str] = field(default_factory=list)


@dataclass
class ModelForm:
    """A URDF slightly outside a closed form's family: a term the closed form cannot express.

    ``relative`` is the term's size over the size of the quantity it enters
    (|ΔH_i| / Σ|terms of H_i|); ``allowance`` the bound on |ΔH| per coordinate that
    the checks may add while ``relative`` stays within the threshold
    (``MODEL_FORM_RTOL``, ``pendverify check --model-form-rtol``).
    """

    what: str
    relative: float
    allowance: np.ndarray
    #: the quantity ``relative`` is measured against
    enters: str = "H1"
    #: what a term beyond the threshold means
    outside: str = "the URDF lies outside the closed form's family"
    #: whether the term's potential grows with the coordinates (|ΔV| is then bounded by the
    #: integral of ``allowance``, not by it at each end)
    potential_grows: bool = False

    def within(self, rtol: float) -> bool:
        return self.relative <= rtol

    def sentence(self, rtol: float) -> str:
        """What the term is, how large, and what the threshold makes of it."""
        if self.within(rtol):
            verdict = f"within the model-form threshold {rtol:g}: the checks allow for it"
        else:
            verdict = (
                f"above the model-form threshold {rtol:g} (--model-form-rtol): {self.outside}, "
                "and no allowance is made"
            )
        return f"{self.what}; that is {self.relative:.3g} of {self.enters}, {verdict}"


def combined(forms: list[ModelForm | None]) -> ModelForm | None:
    """Several terms the closed form cannot express as one: their sizes and allowances add (each
    bounds its own |ΔH|, and |ΔH| of a sum is at most the sum)."""
    present = [f for f in forms if f is not None]
    if len(present) <= 1:
        return present[0] if present else None
    return ModelForm(
        "; ".join(f"{f.what} ({f.relative:.3g} of {f.enters})" for f in present),
        float(sum(f.relative for f in present)),
        np.sum([f.allowance for f in present], axis=0),
        enters="H",
        outside="; ".join(f.outside for f in present),
        potential_grows=any(f.potential_grows for f in present),
    )


#: a function reading a model's map (and parameters) off a URDF in Pinocchio: (model, source, g)
GeometryReader = Callable[[pin.Model, str, "float | None"], UrdfGeometry]
