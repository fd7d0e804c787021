"""Parameter sets: frozen dataclasses of physical quantities, validated at construction.

Each model declares its parameters as dataclass fields whose metadata names the
*kind* of quantity.  The kind fixes the unit and the rule a value must satisfy:

========  ===========================  =========
kind      rule                         unit
========  ===========================  =========
mass      finite and > 0               kg
length    finite and > 0               m
offset    finite and >= 0              m
inertia   finite and >= 0              kg·m²
damping   finite and >= 0              N·m·s/rad (revolute), N·s/m (prismatic)
gravity   finite and >= 0              m/s²
========  ===========================  =========

A bad value raises a ParameterError naming the key, the value and the rule; the files
that hold parameter sets are read by ``pendverify.analytic.params``.
"""

from __future__ import annotations

import dataclasses
import functools
from typing import Any, ClassVar, TypeVar

from pendverify import documents
from pendverify.documents import as_float, is_finite, is_number
from pendverify.errors import ParameterError

#: kind → (the comparison with 0 a value must satisfy, the unit)
KIND_RULES: dict[str, tuple[str, str]] = {
    "mass": ("> 0", "kg"),
    "length": ("> 0", "m"),
    "offset": (">= 0", "m"),
    "inertia": (">= 0", "kg·m²"),
    "damping": (">= 0", "N·m·s/rad or N·s/m"),
    "gravity": (">= 0", "m/s²"),
}


#: kind → its dimension, the exponents of (kg, m, s); a damping coefficient's depends on its joint
#: (N·m·s/rad on a hinge, N·s/m on a slide), which the kind does not say: None
KIND_DIMENSIONS: dict[str, tuple[int, int, int] | None] = {
    "mass": (1, 0, 0),
    "length": (0, 1, 0),
    "offset": (0, 1, 0),
    "inertia": (1, 2, 0),
    "damping": None,
    "gravity": (0, 1, -2),
}


def quantity(kind: str, doc: str) -> Any:
    """A dataclass field holding one physical quantity of the given kind."""
    if kind not in KIND_RULES:
        raise ValueError(f"unknown quantity kind {kind!r}")
    return dataclasses.field(metadata={"kind": kind, "doc": doc})


def _rule_text(kind: str) -> str:
    comparison, unit = KIND_RULES[kind]
    article = "an" if kind[0] in "aeiou" else "a"
    return f"{article} {kind} must be a finite number {comparison} (in {unit})"


@functools.cache
def kind_rules(kind: str) -> tuple:
    """The rules of a quantity of ``kind`` (``pendverify.documents``): a finite number (not a
    boolean) > 0 or >= 0 as ``KIND_RULES`` says; each broken one's sentence is the kind's rule."""
    rule = _rule_text(kind)
    if KIND_RULES[kind][0] == "> 0":
        bound = lambda v: as_float(v) > 0  # noqa: E731
    else:
        bound = lambda v: as_float(v) >= 0  # noqa: E731
    return (is_number, lambda v: f"{rule}; got a {type(v).__name__}"), (is_finite, rule), (bound, rule)


def check_value(source: str, key: str, value: object, kind: str) -> float:
    """Return ``value`` as a float, or raise a ParameterError naming the rule."""
    return as_float(
        documents.check_value(key, value, _kind_key(kind), documents.raising(ParameterError, source))
    )


@functools.cache
def _kind_key(kind: str) -> documents.Key:
    return documents.Key(kind_rules(kind))


P = TypeVar("P", bound="ParameterSet")


@dataclasses.dataclass(frozen=True)
class ParameterSet:
    """Base of every model's parameter set; validates all fields on construction."""

    model: ClassVar[str] = ""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = check_value(
                f"<{self.model} parameters>", f.name, getattr(self, f.name), f.metadata["kind"]
            )
            object.__setattr__(self, f.name, value)

    @classmethod
    def keys(cls) -> tuple[str, ...]:
        """The parameters' names, in the order the dataclass declares them."""
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def schema(cls) -> documents.Table:
        """The set as a table of a document: one key per parameter, its kind's rules."""
        return documents.Table(
            {
                f.name: documents.Key(
                    kind_rules(f.metadata["kind"]), missing=f"missing key ({f.metadata['doc']})"
                )
                for f in dataclasses.fields(cls)
            },
            unknown=f"unknown key; the {cls.model} parameters are {{keys}}",
        )

    @classmethod
    def from_mapping(cls: type[P], data: dict[str, Any], source: str = "<inline>", prefix: str = "") -> P:
        """Build a set from a mapping, rejecting unknown and missing keys (``schema``)."""
        fail = documents.raising(ParameterError, source)
        values = {k: as_float(v) for k, v in documents.check_table(data, cls.schema(), fail, prefix).items()}
        try:
            return cls(**values)
        except ParameterError as exc:  # a rule across fields: name the file
            raise ParameterError(source, prefix + exc.key, exc.value, exc.rule) from None
        except OverflowError:  # a rule across fields computed x**2 beyond a double
            key = max(values, key=lambda k: abs(values[k]))
            raise ParameterError(
                source,
                prefix + key,
                values[key],
                f"too large: the {cls.model} terms built from it overflow a double",
            ) from None

    def as_dict(self) -> dict[str, float]:
        """The values by name: ``{"m1": 1.0, ...}``."""
        return dataclasses.asdict(self)

    def replace(self: P, **changes: float) -> P:
        """A copy with the named values changed, validated as a new set is."""
        return dataclasses.replace(self, **changes)

    def to_toml(self, name: str = "") -> str:
        """The set as a parameter file that ``load_parameter_file`` reads back exactly."""
        lines = [f'model = "{self.model}"']
        if name:
            lines.append(f'name = "{name}"')
        lines.append("")
        lines.append("[parameters]")
        for f in dataclasses.fields(self):
            lines.append(f"{f.name} = {getattr(self, f.name)!r}  # {f.metadata['doc']}")
        return "\n".join(lines) + "\n"
