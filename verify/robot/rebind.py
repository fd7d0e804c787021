"""The URDF of a changed parameter set, for a model the project writes no URDF for (a plug-in).

A plug-in comes with one URDF for one parameter set.  Stress cases and sweeps need
the URDF of *other* sets of the same model.  ``Binding.of`` finds, for each
parameter, the URDF attributes that hold its value, by kind:

=========  ==============================================================
kind       where its value is looked for
=========  ==============================================================
mass       ``<inertial><mass value>``
inertia    ``<inertial><inertia ixx … izz>`` (|value|; the sign is kept)
length     the components of ``<inertial><origin xyz>`` and of a joint's
offset     ``<origin xyz>`` (|value|; the sign is kept)
damping    a joint's ``<dynamics damping>``
gravity    nowhere: Pinocchio takes g from the parameter set
=========  ==============================================================

A value equal (to 1e-12) in more than one parameter of those kinds is ambiguous;
a value found nowhere (a drawing-only length, or a URDF that holds a combination
of parameters, such as an inertia about the joint) is unbound.  Either way the
parameter cannot be changed, and ``rewrite`` says so naming it; it never guesses.
A parameter whose value is 0 is unbound (every zero would match).  What the
rewritten URDF means is checked like any URDF: by the checks.
"""

from __future__ import annotations

import copy
import dataclasses
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from pendverify.analytic import ParameterSet
from pendverify.errors import RebindError
from pendverify.robot.xml_reading import parse_xml

MATCH_RTOL = 1e-12
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
#: kind -> the (element path from the robot, attributes) its value may sit in
SITES: dict[str, tuple[tuple[str, tuple[str, ...]], ...]] = {
    "mass": (("link/inertial/mass", ("value",)),),
    "inertia": (("link/inertial/inertia", _INERTIA),),
    "length": (("link/inertial/origin", ("xyz",)), ("joint/origin", ("xyz",))),
    "offset": (("link/inertial/origin", ("xyz",)), ("joint/origin", ("xyz",))),
    "damping": (("joint/dynamics", ("damping",)),),
}
IN_PINOCCHIO = ("gravity",)  # kinds that are not in the URDF at all


@dataclass(frozen=True)
class Site:
    path: str  # element path, with the element's index: "link/inertial/mass[3]"
    attribute: str
    component: int | None  # for xyz
    sign: float


@dataclass
class Binding:
    """Where each parameter of a set sits in a URDF; ``reasons`` says why the others are unbound."""

    root: ET.Element
    params: ParameterSet
    sites: dict[str, list[tuple[ET.Element, Site]]] = field(default_factory=dict)
    reasons: dict[str, str] = field(default_factory=dict)

    @classmethod
    def of(cls, urdf_text: str, params: ParameterSet, source: str = "<URDF>") -> Binding:
        root = parse_xml(urdf_text, source)  # the strict readers' XML: no DTD, bounded
        binding = cls(root, params)
        candidates = {}
        for f in dataclasses.fields(params):
            kind, value = f.metadata.get("kind"), float(getattr(params, f.name))
            if kind in IN_PINOCCHIO:
                continue
            if kind not in SITES:
                binding.reasons[f.name] = f"its kind {kind!r} is not one the URDF reader knows"
            elif value == 0:
                binding.reasons[f.name] = "its value is 0, which cannot be told apart in the URDF"
            else:
                candidates[f.name] = [s for s in _sites(root, kind) if _same(abs(_value(*s)), value)]
                if not candidates[f.name]:
                    binding.reasons[f.name] = f"its value {value!r} is not in the URDF's {_where(kind)}"
        for name, found in candidates.items():
            clash = sorted(
                other
                for other, theirs in candidates.items()
                if other != name and any(s[0] is t[0] and s[1] == t[1] for s in found for t in theirs)
            )
            if clash:
                binding.reasons[name] = f"its value also belongs to {', '.join(clash)} in the URDF"
            elif found:
                binding.sites[name] = found
        return binding

    def bound(self, name: str) -> bool:
        return name in self.sites

    def link_groups(self) -> dict[str, tuple[str, ...]]:
        """{link: the mass and inertia parameters bound inside its <inertial>} (links with any)."""
        groups = {}
        for link in self.root.findall("link"):
            inside = {id(e) for e in link.iter()}
            names = tuple(
                name
                for name, sites in self.sites.items()
                if self._kind(name) in ("mass", "inertia") and all(id(e) in inside for e, _ in sites)
            )
            if names:
                groups[link.get("name", "?")] = names
        return groups

    def _kind(self, name: str) -> str:
        return next(f.metadata.get("kind") for f in dataclasses.fields(self.params) if f.name == name)

    def rewrite(self, params: ParameterSet) -> str:
        """The URDF with every changed parameter's attributes set to its new value."""
        root = copy.deepcopy(self.root)
        index = {id(old): new for old, new in zip(self.root.iter(), root.iter(), strict=True)}
        for f in dataclasses.fields(params):
            old, new = float(getattr(self.params, f.name)), float(getattr(params, f.name))
            if old == new or f.metadata.get("kind") in IN_PINOCCHIO:
                continue
            if f.name not in self.sites:
                raise RebindError(f"parameter {f.name} cannot be changed in the URDF: {self.reasons[f.name]}")
            for element, site in self.sites[f.name]:
                _set(index[id(element)], site, site.sign * new)
        return ET.tostring(root, encoding="unicode") + "\n"


def _where(kind: str) -> str:
    return " or ".join(f"<{p.replace('/', '><')} {'/'.join(a)}>" for p, a in SITES[kind])


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= MATCH_RTOL * max(abs(a), abs(b))


def _sites(root: ET.Element, kind: str):
    for path, attributes in SITES[kind]:
        for i, element in enumerate(root.findall(path)):
            for attribute in attributes:
                text = element.get(attribute)
                if text is None:
                    continue
                parts = text.split()
                components = range(len(parts)) if attribute == "xyz" else (None,)
                for c in components:
                    try:
                        x = float(parts[c] if c is not None else text)
                    except ValueError:
                        continue
                    yield element, Site(f"{path}[{i}]", attribute, c, -1.0 if x < 0 else 1.0)


def _value(element: ET.Element, site: Site) -> float:
    text = element.get(site.attribute)
    return float(text.split()[site.component] if site.component is not None else text)


def _set(element: ET.Element, site: Site, value: float) -> None:
    if site.component is None:
        element.set(site.attribute, repr(value))
        return
    parts = element.get(site.attribute).split()
    parts[site.component] = repr(value)
    element.set(site.attribute, " ".join(parts))
