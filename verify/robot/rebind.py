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
parameter cannot be changed on its own, and ``rewrite`` says so naming it; it never
guesses.  A parameter whose value is 0 is unbound (every zero would match).

Parameters that share a value (m1 = m2, l1 = l2: textbook sets often do) form a
*group* (``groups``): the URDF cannot say which of its sites is whose, but all of
them can be changed together.  ``rewrite`` accepts a set in which every member of
a group has one new value, and writes it at every site that held the group's value;
members given different values are refused naming them.  What the rewritten URDF
means is checked like any URDF: by the checks.

These rules do not depend on what holds the values: ``match`` applies them to the places
a holder lists (a URDF's attributes here; a loaded Pinocchio model's fields in
``pendverify.robot.model_rebind``), and ``changes`` lists what a new set writes where.
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


class Bound:
    """What every binding answers: which parameters are bound alone, which share a value.

    ``sites``: parameter → the sites holding its value; ``groups``: the parameters that share a
    value (module docstring) → their sites; ``reasons``: parameter → why it is bound alone nowhere.
    """

    params: ParameterSet
    sites: dict
    reasons: dict[str, str]
    groups: dict

    def bound(self, name: str) -> bool:
        return name in self.sites

    def group_of(self, name: str) -> tuple[str, ...] | None:
        """The group of parameters that share ``name``'s value (module docstring), or None."""
        return next((g for g in self.groups if name in g), None)

    def _kind(self, name: str) -> str:
        return next(f.metadata.get("kind") for f in dataclasses.fields(self.params) if f.name == name)


def match(binding: Bound, found, holder: str, where) -> None:
    """Fill ``binding``'s sites, groups and reasons (module docstring), whatever holds the values.

    ``found(kind)`` is the list of (element, ``Site``, value) a parameter of that kind may sit at,
    or, for a kind ``holder`` (``"the URDF"``) does not hold, the reason in words; ``where(kind)``
    names those places in words.  Sites are told apart by ``Site`` alone (its path names the element)."""
    candidates = {}
    for f in dataclasses.fields(binding.params):
        kind, value = f.metadata.get("kind"), float(getattr(binding.params, f.name))
        if kind in IN_PINOCCHIO:
            continue
        places = found(kind)
        if isinstance(places, str):
            binding.reasons[f.name] = places
        elif value == 0:
            binding.reasons[f.name] = f"its value is 0, which cannot be told apart in {holder}"
        else:
            candidates[f.name] = [(e, s) for e, s, v in places if _same(abs(v), value)]
            if not candidates[f.name]:
                binding.reasons[f.name] = f"its value {value!r} is not in {holder}'s {where(kind)}"
    clashes = {}
    for name, mine in candidates.items():
        clashes[name] = sorted(
            other
            for other, theirs in candidates.items()
            if other != name and any(s == t for _, s in mine for _, t in theirs)
        )
        if clashes[name]:
            binding.reasons[name] = f"its value also belongs to {', '.join(clashes[name])} in {holder}"
        elif mine:
            binding.sites[name] = mine
    for group in _components(clashes):
        merged: dict = {}
        for name in group:
            merged.update({s: (e, s) for e, s in candidates[name]})
        binding.groups[group] = list(merged.values())


def changes(binding: Bound, params: ParameterSet, holder: str):
    """(element, ``Site``, value to write) for every parameter of ``params`` that differs from
    ``binding``'s; a parameter bound nowhere, or a group given different values, is refused by name."""
    for f in dataclasses.fields(params):
        old, new = float(getattr(binding.params, f.name)), float(getattr(params, f.name))
        if old == new or f.metadata.get("kind") in IN_PINOCCHIO:
            continue
        group = binding.group_of(f.name)
        if group is not None:
            values = {float(getattr(params, g)) for g in group}
            if len(values) > 1:
                raise RebindError(
                    f"parameter {f.name} cannot be changed in {holder} apart from "
                    f"{', '.join(g for g in group if g != f.name)}: {binding.reasons[f.name]}; "
                    "they can be changed together, to one value"
                )
            sites = binding.groups[group]
        elif f.name in binding.sites:
            sites = binding.sites[f.name]
        else:
            raise RebindError(f"parameter {f.name} cannot be changed in {holder}: {binding.reasons[f.name]}")
        for element, site in sites:
            yield element, site, site.sign * new


@dataclass
class Binding(Bound):
    """Where each parameter of a set sits in a URDF; ``reasons`` says why the others are unbound."""

    root: ET.Element
    params: ParameterSet
    sites: dict[str, list[tuple[ET.Element, Site]]] = field(default_factory=dict)
    reasons: dict[str, str] = field(default_factory=dict)
    #: the parameters that share a value, each group sorted (module docstring), and its sites
    groups: dict[tuple[str, ...], list[tuple[ET.Element, Site]]] = field(default_factory=dict)

    @classmethod
    def of(cls, urdf_text: str, params: ParameterSet, source: str = "<URDF>") -> Binding:
        root = parse_xml(urdf_text, source)  # the strict readers' XML: no DTD, bounded
        binding = cls(root, params)

        def found(kind: str):
            if kind not in SITES:
                return f"its kind {kind!r} is not one the URDF reader knows"
            return [(e, s, _value(e, s)) for e, s in _sites(root, kind)]

        match(binding, found, "the URDF", _where)
        return binding

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

    def rewrite(self, params: ParameterSet) -> str:
        """The URDF with every changed parameter's attributes set to its new value."""
        root = copy.deepcopy(self.root)
        index = {id(old): new for old, new in zip(self.root.iter(), root.iter(), strict=True)}
        for element, site, value in changes(self, params, "the URDF"):
            _set(index[id(element)], site, value)
        return ET.tostring(root, encoding="unicode") + "\n"


def _components(clashes: dict[str, list[str]]) -> list[tuple[str, ...]]:
    """The groups of parameters linked by shared sites (connected components), each sorted."""
    seen: set[str] = set()
    out = []
    for name in clashes:
        if name in seen or not clashes[name]:
            continue
        group, todo = set(), [name]
        while todo:
            n = todo.pop()
            if n not in group:
                group.add(n)
                todo += clashes[n]
        seen |= group
        out.append(tuple(sorted(group)))
    return out


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
