"""One exception hierarchy for everything pendverify rejects.

Every error carries the place it came from (file, key), the offending value and
the rule it broke, so that the message alone tells a user what to fix.  The CLI
prints ``str(error)`` and exits with status 2; no traceback reaches the user.
"""

from __future__ import annotations

from dataclasses import dataclass


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
class UrdfShapeError(PendverifyError):
    """A URDF does not have the structure a model needs."""

    source: str
    problem: str

    def __str__(self) -> str:
        return f"{self.source}: {self.problem}"


@dataclass
class UnknownNameError(PendverifyError):
    """A name (model, check, effect) is not one of the known ones."""

    kind: str
    name: str
    known: tuple[str, ...]

    def __str__(self) -> str:
        return f"unknown {self.kind} {self.name!r}; known: {', '.join(self.known)}"


class FastPathError(InputError):
    """A scene uses an effect the compiled back ends do not compile (time-varying, saturated)."""
