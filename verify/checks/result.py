"""What a check is: ``Check``, one comparison and its constant K.

What it reports is an ``Evidence`` (``pendverify.checks.evidence``).  The checks themselves
are listed in ``pendverify.checks.catalogue``; what one measures at a state is in
``pendverify.checks.quantities``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pendverify.analytic import ClosedFormModel
    from pendverify.checks.quantities import Measure, Terms
    from pendverify.robot.system import PinocchioSystem


@dataclass(frozen=True)
class Check:
    name: str
    pinocchio: str
    closed_form: str
    K: float
    #: the check's measure at every state of a batch (``pendverify.checks.quantities``)
    measure: Callable[[Terms], Measure]
    #: "" when the check applies to this model and system, else why it is not run
    requires: Callable[[ClosedFormModel, PinocchioSystem | None], str] = lambda model, system: ""
    #: whether the Pinocchio side is computed by its world-frame recursions (then A counts)
    world_frame: bool = True
