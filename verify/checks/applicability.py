"""Which checks apply to a model (and its URDF), and what a derived closed form means for the evidence.

A check is not run when there is nothing to compare: ``coriolis`` and ``skew`` need a
matrix C (a ``BiasOnlyModel`` gives only C·q̇); ``det`` and ``minverse`` need a
hand-written det M and M⁻¹ (the interface's defaults derive them from M, by LU and by
solving); ``damping`` needs a URDF that declares ``<dynamics damping>``; ``energy`` needs V, which a
model may leave out (``potential_energy`` is optional) and a model deriving M, H and C·q̇ from its q̈
(``mass_from_acceleration``) does not give.  Each
``requires`` function returns "" when its check applies, else the reason, which the
report prints.  ``derived_notes`` says what the model left to the interface's defaults
(what is derived, and how: ``pendverify.analytic.forms.INTERFACE``).
"""

from __future__ import annotations

from pendverify.analytic.forms import INTERFACE, STATES, TOLERANCE


def needs_mass_matrix(model, system) -> str:
    """A ``requires``: the check compares M or what is built with it, which q̈ alone may not give
    (it does where the model derives M, H and C·q̇ from q̈: ``mass_from_acceleration``)."""
    if model.has_mass_matrix or model.mass_from_acceleration:
        return ""
    return (
        f"not run: {_class(model).__name__} gives q̈ alone and {model.without_mass_matrix}; "
        "q̈ is checked by aba"
    )


def needs_mass_matrix_and(requires):
    """A ``requires``: ``needs_mass_matrix``, then ``requires``."""

    def both(model, system) -> str:
        return needs_mass_matrix(model, system) or requires(model, system)

    return both


def needs_potential_energy(model, system) -> str:
    """A ``requires``: the check compares V, which a model may leave out (it is optional) and a model
    deriving M, H and C·q̇ from q̈ does not give."""
    if model.mass_from_acceleration:
        return (
            f"not run: {_class(model).__name__} derives M, H and C·q̇ from its q̈ at states, not V "
            "(the energy check needs V(q), an integral of H over q)"
        )
    if _class(model).has_potential_energy():
        return ""
    return (
        f"not run: the model gives no potential energy V(q) ({_class(model).__name__} writes no "
        "potential_energy); H is checked by gravity"
    )


def needs_matrix_c(model, system) -> str:
    if model.has_coriolis_matrix:
        return ""
    name = model.__name__ if isinstance(model, type) else type(model).__name__
    return (
        f"not run: {name} gives the force C·q̇ (coriolis_force), not a matrix C; "
        "C·q̇ is checked by rnea and aba"
    )


def _class(model) -> type:
    return model if isinstance(model, type) else type(model)


def hand_written(method: str):
    """A ``requires``: the check compares a hand-written closed form, so a derived one is not run."""

    def requires(model, system) -> str:
        if method in _class(model).hand_written():
            return ""
        what, how = INTERFACE[method].derived
        return f"not run: {what} is derived {how}, not hand-written: nothing to check"

    return requires


def derived_notes(model) -> list[str]:
    """What the model left to the interface's defaults and what that means for the evidence.

    ``aba`` runs on a derived q̈ too, but it is then weaker evidence: the derived
    M⁻¹(B u + W w − D q̇ − C q̇ − H) and Pinocchio's ABA of the same τ = B u + W w − D q̇
    see B, W and D alike, so aba checks only M and C·q̇ + H (which crba and rnea
    check directly) composed by the solve the simulator uses — not B or W, which the
    URDF does not define (``pendverify sympy`` compares them with the input power),
    and D only through ``damping`` (the URDF's <dynamics damping>).
    """
    written = set(_class(model).hand_written())
    notes = []
    if model.mass_from_acceleration:
        notes.append(
            f"crba, gravity, rnea: {model.mass_from_acceleration}; the inertia and gravity scales "
            "their tolerances are judged against are the URDF's"
        )
        return notes
    if not model.has_mass_matrix:
        notes.append(
            "aba: q̈ is the model's own; the model gives no M, so the sizes its tolerance is judged "
            "against (inertia scale, ‖M‖, ‖M⁻¹‖, gravity scale) are the URDF's"
        )
        return notes
    if "acceleration" not in written:
        notes.append(
            "aba: q̈ is derived from the model's M, C, H, D, B, W, not hand-written: aba checks M and "
            "C·q̇ + H composed (the same τ = B u + W w − D q̇ enters both sides), not B or W, and no "
            "closed form of q̈; B and W are compared only by pendverify sympy"
        )
    derived = [
        " ".join(method.derived)
        for name, method in INTERFACE.items()
        if method.kind in (TOLERANCE, STATES) and name not in written
    ]
    if derived:
        notes.append("derived, not hand-written: " + "; ".join(derived))
    return notes


def needs_urdf_damping(model, system) -> str:
    if system is None or system.urdf_damping() is not None:
        return ""
    return "not run: the URDF declares no <dynamics damping>, so there is nothing to compare D with"
