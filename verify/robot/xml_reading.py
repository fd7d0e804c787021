"""The XML of a robot description, read safely and within bounds, and a URDF's as urdfdom sees it.

* ``read_xml``: the document parsed once, by expat with namespace processing and prefixes
  reported, into an ``XmlDocument`` holding two trees of the same elements: ``root``, names
  resolved as ElementTree spells them (``{uri}tag``), and ``written``, names as written
  (``drake:joint``).  A DOCTYPE, an entity declaration or an external reference is refused with
  ``defusedxml``'s exception for it (as ``defusedxml.ElementTree.fromstring(text,
  forbid_dtd=True)`` does), so nothing the file declares can change what a number says; the text
  is at most ``MAX_XML_CHARACTERS`` long and nested at most ``MAX_XML_DEPTH`` elements deep (the
  readers walk the tree recursively; a URDF is about 6 deep, an MJCF chain of n bodies n + 3).
  Literal tabs and line breaks inside attribute values are kept (an XML parser would report
  spaces).  ``parse_xml`` is its resolved tree.
* ``as_urdfdom_reads``: a URDF's tree the way urdfdom (TinyXML, which knows no namespaces) reads
  it, from the tree as written: ``<robot xmlns="http://drake.mit.edu">`` is a ``<robot>``, and an
  element or attribute with a prefix (Drake's ``<drake:joint>``, ``drake:declare_convex``) is one
  urdfdom never looks at; both are dropped, with whatever an element holds (``xmlns``
  declarations are not attributes in either tree); ``ignored_extensions`` lists such elements
  for a note.
"""

from __future__ import annotations

import copy
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from xml.parsers import expat

import defusedxml
from defusedxml import DTDForbidden, EntitiesForbidden, ExternalReferenceForbidden

from pendverify.display import shortened
from pendverify.errors import UrdfShapeError
from pendverify.robot.urdf_numbers import RAW_WHITESPACE

__all__ = [
    "MAX_XML_CHARACTERS",
    "MAX_XML_DEPTH",
    "XmlDocument",
    "as_urdfdom_reads",
    "ignored_extensions",
    "parse_xml",
    "read_xml",
]

#: characters of a description's XML (published URDFs and MJCFs are at most a few MB; meshes are
#: separate files)
MAX_XML_CHARACTERS = 64 * 2**20
#: elements nested in one another, root included
MAX_XML_DEPTH = 256


@dataclass(frozen=True)
class XmlDocument:
    """A description's XML from its one parse: the tree with names resolved and as written."""

    #: names resolved, as ElementTree spells them: ``{uri}tag``, ``{uri}attribute``
    root: ET.Element
    #: names as written (``drake:joint``); ``xmlns`` declarations are not attributes here either
    written: ET.Element


def parse_xml(text: str, source: str) -> ET.Element:
    """The XML of a description, names resolved (``read_xml``'s ``root``)."""
    return read_xml(text, source).root


def read_xml(text: str, source: str) -> XmlDocument:
    """The XML of a description, parsed once: DTDs and entities refused, its size and depth
    bounded, tabs/line breaks in attributes kept."""
    if len(text) > MAX_XML_CHARACTERS:
        raise UrdfShapeError(
            source, f"{len(text)} characters of XML exceed the limit of {MAX_XML_CHARACTERS} characters"
        )
    exposed = _expose_attribute_whitespace(text)
    try:
        # Literal tabs and line breaks inside attribute values are character references in
        # ``exposed``, which XML keeps instead of normalising them to spaces.
        document = _parse(exposed)
    except expat.ExpatError:
        document = _parse_reporting(text, source)  # the error at its place in the text as written
    except defusedxml.DefusedXmlException as exc:
        raise UrdfShapeError(source, f"XML with a DOCTYPE or entities is refused ({exc})") from None
    _check_depth(document.root, source)
    return document


def _parse_reporting(text: str, source: str) -> XmlDocument:
    """``_parse(text)``, its failure one ``UrdfShapeError`` naming line and column."""
    try:
        return _parse(text)
    except defusedxml.DefusedXmlException as exc:
        raise UrdfShapeError(source, f"XML with a DOCTYPE or entities is refused ({exc})") from None
    except expat.ExpatError as exc:
        reason = expat.ErrorString(exc.code)
        raise UrdfShapeError(
            source, f"malformed XML at line {exc.lineno}, column {exc.offset + 1}: {reason}"
        ) from None


#: separates namespace URI, local name and prefix in the names expat reports (a control
#: character XML 1.0 allows nowhere in a document, so it cannot occur in a URI)
_SEP = "\x1f"


def _parse(text: str) -> XmlDocument:
    """Both trees of ``text`` from one expat parse with namespace processing and prefixes
    reported; a DOCTYPE, an entity declaration or an external reference raises defusedxml's
    exception for it (as ``defusedxml.ElementTree.fromstring(text, forbid_dtd=True)``)."""
    resolved, written = ET.TreeBuilder(), ET.TreeBuilder()
    parser = expat.ParserCreate(namespace_separator=_SEP)
    parser.namespace_prefixes = True
    parser.buffer_text = True
    parser.ordered_attributes = True

    def start(name: str, attributes: list[str]) -> None:
        pairs = [(_names(key), value) for key, value in zip(attributes[::2], attributes[1::2], strict=True)]
        tag, as_written = _names(name)
        resolved.start(tag, {key[0]: value for key, value in pairs})
        written.start(as_written, {key[1]: value for key, value in pairs})

    def end(name: str) -> None:
        tag, as_written = _names(name)
        resolved.end(tag)
        written.end(as_written)

    def data(chunk: str) -> None:
        resolved.data(chunk)
        written.data(chunk)

    def doctype(name, system_id, public_id, _has_internal_subset) -> None:
        raise DTDForbidden(name, system_id, public_id)

    def entity(name, _is_parameter, value, base, system_id, public_id, notation_name) -> None:
        raise EntitiesForbidden(name, value, base, system_id, public_id, notation_name)

    def unparsed_entity(name, base, system_id, public_id, notation_name) -> None:
        raise EntitiesForbidden(name, None, base, system_id, public_id, notation_name)

    def external(context, base, system_id, public_id) -> None:
        raise ExternalReferenceForbidden(context, base, system_id, public_id)

    parser.StartElementHandler, parser.EndElementHandler = start, end
    parser.CharacterDataHandler = data
    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler, parser.UnparsedEntityDeclHandler = entity, unparsed_entity
    parser.ExternalEntityRefHandler = external
    parser.Parse(text, True)
    return XmlDocument(resolved.close(), written.close())


def _names(reported: str) -> tuple[str, str]:
    """(resolved, as written) of a name expat reports as ``uri·local·prefix``, ``uri·local``
    (a default namespace: written without a prefix) or ``local``."""
    parts = reported.split(_SEP)
    if len(parts) == 1:
        return reported, reported
    uri, local = parts[0], parts[1]
    return f"{{{uri}}}{local}", (f"{parts[2]}:{local}" if len(parts) == 3 else local)


def _check_depth(root: ET.Element, source: str) -> None:
    """Refuse a tree nested deeper than ``MAX_XML_DEPTH`` (walked without recursion)."""
    stack = [(root, 1, f"<{root.tag}>")]
    while stack:
        element, depth, path = stack.pop()
        if depth > MAX_XML_DEPTH:
            raise UrdfShapeError(
                source,
                f"elements nested more than {MAX_XML_DEPTH} deep (below {shortened(path, 80)}…); "
                f"refused: the limit is {MAX_XML_DEPTH}",
            )
        stack.extend((child, depth + 1, f"{path}<{child.tag}>" if depth < 3 else path) for child in element)


_ATTRIBUTE = re.compile(r"""(?P<head>[\s][^\s=<>"'/]+\s*=\s*)(?P<quote>["'])(?P<value>[^<]*?)(?P=quote)""")


def _expose_attribute_whitespace(text: str) -> str:
    """Write literal tabs/CR/LF inside quoted attribute values as character references."""

    def escape(match: re.Match[str]) -> str:
        value = match["value"]
        if not any(c in value for c in RAW_WHITESPACE):
            return match[0]
        for char, ref in RAW_WHITESPACE.items():
            value = value.replace(char, ref)
        return f"{match['head']}{match['quote']}{value}{match['quote']}"

    return _ATTRIBUTE.sub(escape, text)


def as_urdfdom_reads(document: XmlDocument) -> ET.Element:
    """A URDF's tree as urdfdom reads it (see the module docstring): a copy of the tree as
    written without prefixed elements and attributes."""
    root = copy.deepcopy(document.written)
    _drop_prefixed(root)
    return root


def ignored_extensions(document: XmlDocument) -> dict[str, int]:
    """{name as written: count} of the prefixed elements a URDF holds (``drake:rotor_inertia``),
    which urdfdom, and hence the model, leaves out; {} for a file without any."""
    counts: dict[str, int] = {}
    stack = [document.written]
    while stack:
        element = stack.pop()
        for child in element:
            if ":" in child.tag:
                counts[child.tag] = counts.get(child.tag, 0) + 1
            else:
                stack.append(child)
    return dict(sorted(counts.items()))


def _drop_prefixed(element: ET.Element) -> None:
    """Remove what urdfdom never reads: prefixed elements and attributes."""
    for attr in [a for a in element.attrib if ":" in a]:
        del element.attrib[attr]
    for child in list(element):
        if ":" in child.tag:
            element.remove(child)
        else:
            _drop_prefixed(child)
