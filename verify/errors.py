"""One exception hierarchy for everything pendverify rejects.

Every error carries the place it came from (file, key), the offending value and
the rule it broke, so that the message alone tells a user what to fix.  The CLI
prints ``str(error)`` and exits with status 2; no traceback reaches the user.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path


class PendverifyError(Exception):
    """Root of every error pendverify raises on purpose."""


@dataclass
class InputError(PendverifyError):
    """A value in a user's file breaks a rule.

    ``source`` names the file (or ``"<inline>"``), ``key`` the dotted key, ``value``
    the value found and ``rule`` what the value must satisfy.
    """

    source: str
    key: str
    value: object
    rule: str

    def __str__(self) -> str:
        return f"{self.source}: key '{self.key}' = {self.value!r}: {self.rule}"


class ParameterError(InputError):
    """A parameter set is invalid."""


@dataclass
class PlaceError(PendverifyError):
    """A problem at a place: ``source`` names the file (", line N" where known)."""

    source: str
    problem: str

    def __str__(self) -> str:
        return f"{self.source}: {self.problem}"


@dataclass
class ExcerptError(PendverifyError):
    """A problem at a place in an expression: the headline (file, key, rule and fix), then the
    fragment of the expression around the place and a caret under it, on two more lines.

    One logical error: the CLI prints the headline on one line and keeps the two lines below it
    (``pendverify.exitcodes.classify``).  ``column`` is the caret's position in ``fragment``.
    """

    headline: str
    fragment: str
    column: int

    def __str__(self) -> str:
        return f"{self.headline}\n{self.pointer()}"

    def pointer(self) -> str:
        """The fragment and the caret under the place, each indented by two spaces."""
        return f"  {self.fragment}\n  {' ' * self.column}^"


#: the most characters of an expression a message quotes around the place of a problem
EXCERPT_WIDTH = 80


def excerpt(text: str, at: int, width: int = EXCERPT_WIDTH) -> tuple[str, int]:
    """(at most ``width`` characters of ``text`` around position ``at`` on one line, the position
    of ``at`` in it): line breaks and tabs become spaces, a cut end shows "…"."""
    one = "".join(" " if c.isspace() else c for c in text)
    at = max(0, min(at, len(one)))
    if len(one) <= width:
        return one, at
    start = max(0, min(at - width // 2, len(one) - width))
    piece = one[start : start + width]
    head = "…" if start > 0 else ""
    return head + piece + ("…" if start + width < len(one) else ""), len(head) + at - start


class UrdfShapeError(PlaceError):
    """A URDF does not have the structure a model needs."""


@dataclass
class UnknownNameError(PendverifyError):
    """A name (model, check, effect) is not one of the known ones."""

    kind: str
    name: str
    known: tuple[str, ...]

    def __str__(self) -> str:
        return f"unknown {self.kind} {self.name!r}; known: {', '.join(self.known)}"


class SceneError(InputError):
    """A scene file breaks a rule (``pendverify.simulation.scene``)."""


class TrajectoryError(InputError):
    """A saved trajectory cannot be rendered (``pendverify.viz.animation``)."""


@dataclass
class IllConditionedError(PendverifyError):
    """M(q) is too close to singular (or Pinocchio's terms too large) for a comparison to mean something.

    Raised by ``pendverify.checks.trust.check_conditioning``; ``limit`` is the trust limit
    (``pendverify.checks.trust.REFUSE_REL``) the rounding bound exceeded.
    """

    what: str
    q: list
    kappa_scaled: float
    bound: float
    amplification: float = 1.0
    spread: float = 1.0
    #: the bound comes from the scale spread, not from κ̃ and A
    by_spread: bool = False
    limit: float = field(kw_only=True)

    def __str__(self) -> str:
        q = ", ".join(f"{x:.6g}" for x in self.q)
        terms = (
            f" and Pinocchio's terms are {self.amplification:.2g}× the result"
            if self.amplification >= 10
            else ""
        )
        if self.by_spread:
            return (
                f"{self.what} at q = ({q}): cannot be verified: M's diagonal scales span a factor "
                f"{self.spread**2:.3g}, so an error of a relative {self.bound:.2g} in the smaller ones would "
                f"not show against rounding ({self.bound:.2g} > {self.limit:g}, the trust limit); refused"
            )
        return (
            f"{self.what} at q = ({q}): too ill-conditioned to verify: κ̃(M) = {self.kappa_scaled:.3g} "
            f"after diagonal scaling{terms}, so rounding alone can cause a relative error of "
            f"{self.bound:.2g} > {self.limit:g} (the trust limit); refused"
        )


class CertificateError(PendverifyError):
    """A certificate is malformed, tampered with, or no longer holds."""


class SweepError(InputError):
    """A sweep file breaks a rule."""


class RebindError(PendverifyError):
    """A parameter cannot be changed in the URDF."""


class FastPathError(InputError):
    """A scene uses an effect the compiled back ends do not compile (time-varying, saturated)."""


class BundleNameError(InputError):
    """A set's name cannot name files: it must be a plain file name inside the output folder."""


class SigningError(PendverifyError):
    """A key cannot be read or written, or a signature does not hold (``pendverify.certify.signing``)."""


class FileAccessError(PlaceError):
    """A user's file cannot be read, or an output cannot be written: the path and the OS's reason."""

    def __init__(self, path: str, action: str, reason: str):
        super().__init__(path, f"cannot {action} it: {reason}")  # action: "read" or "write"


#: the next step for a file that is not there: the worked examples hold every kind of file
COPY_EXAMPLES = (
    "`pendverify example` lists the worked examples and `pendverify example NAME DIR` copies one's files "
    "into DIR"
)


@dataclass
class UserFileError(PendverifyError):
    """A file the user named cannot be used as given: it is missing, unreadable, a folder, or a
    file of another kind.  One sentence: what is wrong, the file (with the folder a relative path
    was looked up in) and the next step.  Made by ``missing_file``, ``unreadable_file``,
    ``folder_given`` and ``wrong_kind``."""

    problem: str
    path: str
    next_step: str
    #: the working folder a relative ``path`` was looked up in ("" for an absolute path)
    folder: str = ""

    def __str__(self) -> str:
        where = f" (relative to {self.folder})" if self.folder else ""
        return f"{self.problem}: {self.path}{where}; {self.next_step}"


def _folder_of(path: str | Path) -> str:
    """The working folder a relative path is read from; "" for an absolute one."""
    return "" if Path(path).is_absolute() else os.getcwd()


def missing_file(path: str | Path, what: str = "file", next_step: str = COPY_EXAMPLES) -> UserFileError:
    """``what`` (a "parameter file", a "scene file", ...) is not at ``path``; ``next_step``: where
    to get one (by default, the worked examples)."""
    return UserFileError(f"{what} not found", str(path), f"check the path; {next_step}", _folder_of(path))


def unreadable_file(path: str | Path, what: str, reason: str) -> UserFileError:
    """``path`` exists but the OS refuses to read it (``reason``: its words, "Permission denied")."""
    return UserFileError(
        f"cannot read the {what} ({reason})",
        str(path),
        "make it readable (ls -l shows its permissions) or give a copy you can read",
        _folder_of(path),
    )


def folder_given(path: str | Path, what: str) -> UserFileError:
    """A folder where a ``what`` file was expected."""
    return UserFileError(f"a folder, not a {what}", str(path), f"give the {what} inside it", _folder_of(path))


def wrong_kind(path: str | Path, what: str, found: str, next_step: str) -> UserFileError:
    """``path`` is a ``found`` (a "text model file", a "robot description") where a ``what`` was expected."""
    return UserFileError(f"not a {what} but a {found}", str(path), next_step, _folder_of(path))


class UserCodeError(PlaceError):
    """A user's model file raised (or called sys.exit) while pendverify ran it."""


class IntegrationError(PlaceError):
    """The integrator cannot follow a scene's dynamics (``source`` names the scene)."""


class OptionConflictError(PendverifyError):
    """Two options (or an option and an argument) that cannot go together on the command line."""
