"""One finding of a diagnosis, as the report, the JSON document, the review page and JUnit carry it.

A failing model's diagnosis is a list of ``Finding``; ``--json`` writes it under
``diagnoses``, one list per model label, each finding an object (``as_dict``):

==============  ===========================================================================
field           meaning
==============  ===========================================================================
kind            ``entry`` (an entry that differs), ``pattern`` (the shape of its
                difference over the states), ``repair`` (an edit of the model's own
                expressions after which every check passes on every state, confirmed or
                at these parameter values only), ``parameters``
                (the hand model is this robot with other inertial parameters),
                ``convention`` (a coordinate or inertia convention trap), ``structural``
                (no inertial parameters explain the difference)
quantity        ``M``, ``C``, ``Cqdot``, ``H``, ``V``, ``D``, ``B``, ``W``, ``Minv``, ``detM``,
                ``qddot``, or null for a finding about the whole model
index           the entry, 1-based as a derivation writes it (``[2, 2]`` for M's last entry
                of a double pendulum, ``[1]`` for H's first, ``[]`` for a scalar or none)
message         the finding in words, as the text report prints it
==============  ===========================================================================

A ``repair`` adds ``written`` and ``suggested`` (the entry before and after the edit, in
SymPy syntax over the model's own names), ``suggested_source`` (the edit in the model's own
notation: LaTeX for a LaTeX file, SymPy syntax for a text file, the Python expression for
a class), ``location`` (file, key or method, and entry), ``checks_pass`` (true when every
check was re-run on every state at the parameter file's values and passed) and ``confirmed``
(true only when it also passed at perturbed parameter sets, the description rewritten for
each, every parameter of the edit moved on its own, and no other edit passed: the same
function of the parameters, not the same numbers; ``pendverify.diagnosis.repair``).  For a
model SymPy cannot read, a repair is an edit of the parameters its code is given
(``pendverify.diagnosis.parameter_repair``): ``written`` the parameter(s) the code is given
(``m2``; ``l1, l2`` for an exchange), ``suggested`` what to give it instead (``m2/2``; ``l2, l1``),
and no quantity or index.  A
``parameters`` finding adds
``link``, ``parameter``, ``model_value`` and ``urdf_value``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

KINDS = ("entry", "pattern", "repair", "parameters", "convention", "structural")
QUANTITIES = ("M", "C", "Cqdot", "H", "V", "D", "B", "W", "Minv", "detM", "qddot")


@dataclass(frozen=True)
class Finding:
    """One thing a diagnosis found (module docstring)."""

    kind: str
    message: str
    quantity: str | None = None
    index: tuple[int, ...] = ()
    #: the kind's own fields (``repair``: written, suggested, ...; ``parameters``: link, ...)
    details: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"finding kind {self.kind!r}: must be one of {', '.join(KINDS)}")
        if self.quantity is not None and self.quantity not in QUANTITIES:
            raise ValueError(f"finding quantity {self.quantity!r}: must be one of {', '.join(QUANTITIES)}")

    def as_dict(self) -> dict:
        """The JSON object of ``diagnoses`` (module docstring)."""
        return {
            "kind": self.kind,
            "quantity": self.quantity,
            "index": list(self.index),
            "message": self.message,
            **self.details,
        }

    def __str__(self) -> str:
        return self.message


#: entries the text report names one by one; the rest are counted (all are in ``--json``)
TEXT_ENTRIES = 6


def text_lines(findings: list[Finding]) -> list[str]:
    """The diagnosis as the text report prints it, short: each entry with the shape of its
    difference on one line (the first ``TEXT_ENTRIES``, the rest counted), then the other findings."""
    listed = [f for f in findings if f.kind == "entry"]
    shapes = {(f.quantity, f.index): f for f in findings if f.kind == "pattern"}
    lines = []
    for entry in listed[:TEXT_ENTRIES]:
        shape = shapes.get((entry.quantity, entry.index))
        lines.append(entry.message + (f"; {shape.message.split(': ', 1)[1]}" if shape else ""))
    if len(listed) > TEXT_ENTRIES:
        rest = [f.message.split(":", 1)[0].split(" (", 1)[0] for f in listed[TEXT_ENTRIES:]]
        lines.append(f"{len(rest)} more entries differ ({', '.join(rest)}): all of them are in --json")
    return lines + [f.message for f in findings if f.kind not in ("entry", "pattern")]
