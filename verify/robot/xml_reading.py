"""The XML of a robot description, read safely and within bounds, and a URDF's as urdfdom sees it.

* ``parse_xml``: the document parsed with ``defusedxml`` and ``forbid_dtd=True`` (a DOCTYPE or
  entity is refused, so nothing the file declares can change what a number says), at most
  ``MAX_XML_CHARACTERS`` long and nested at most ``MAX_XML_DEPTH`` elements deep (the readers
  walk the tree recursively; a URDF is about 6 deep, an MJCF chain of n bodies n + 3).  Literal
  tabs and line breaks inside attribute values are kept (an XML parser would report spaces).
  Namespaces are resolved, as ElementTree does: ``{uri}tag``.
* ``parse_xml_as_urdfdom_reads``: a URDF's tree with names as written, the way urdfdom
  (TinyXML, which knows no namespaces) reads it: ``<robot xmlns="http://drake.mit.edu">`` is a
  ``<robot>``, and an element or attribute with a prefix (Drake's ``<drake:joint>``,
  ``drake:declare_convex``) is one urdfdom never looks at; both are dropped, with whatever an
  element holds, as are the ``xmlns`` declarations; ``ignored_extensions`` lists such elements
  for a note.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from xml.parsers import expat

import defusedxml
import defusedxml.ElementTree as DET

from pendverify.display import shortened
from pendverify.errors import UrdfShapeError
from pendverify.robot.urdf_numbers import RAW_WHITESPACE

__all__ = [
    "MAX_XML_CHARACTERS",
    "MAX_XML_DEPTH",
    "ignored_extensions",
    "parse_xml",
    "parse_xml_as_urdfdom_reads",
]

#: characters of a description's XML (published URDFs and MJCFs are at most a few MB; meshes are
#: separate files)
MAX_XML_CHARACTERS = 64 * 2**20
#: elements nested in one another, root included
MAX_XML_DEPTH = 256


def parse_xml(text: str, source: str) -> ET.Element:
    """The XML of a description, DTDs and entities refused, its size and depth bounded, tabs/line
    breaks in attributes kept."""
    if len(text) > MAX_XML_CHARACTERS:
        raise UrdfShapeError(
            source, f"{len(text)} characters of XML exceed the limit of {MAX_XML_CHARACTERS} characters"
        )
    try:
        root = DET.fromstring(text, forbid_dtd=True)
    except defusedxml.DefusedXmlException as exc:
        raise UrdfShapeError(source, f"XML with a DOCTYPE or entities is refused ({exc})") from None
    except ET.ParseError as exc:
        line, column = exc.position
        reason = re.sub(r":\s*line \d+, column \d+$", "", str(exc))
        raise UrdfShapeError(source, f"malformed XML at line {line}, column {column + 1}: {reason}") from None
    exposed = _expose_attribute_whitespace(text)
    if exposed != text:
        # Same document, but literal tabs and line breaks inside attribute values are now
        # character references, which XML keeps instead of normalising them to spaces.
        try:
            root = DET.fromstring(exposed, forbid_dtd=True)
        except ET.ParseError:  # cannot happen for a well-formed file; keep the plain reading
            pass
    _check_depth(root, source)
    return root


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


def parse_xml_as_urdfdom_reads(text: str, source: str, checked: bool = False) -> ET.Element:
    """A URDF's tree as urdfdom reads it (see the module docstring); ``text`` is checked by
    ``parse_xml`` first, so every refusal names the same rules (``checked``: the caller has
    run ``parse_xml`` on this very text already)."""
    if not checked:
        parse_xml(text, source)
    try:
        root = _names_as_written(_expose_attribute_whitespace(text), source)
    except expat.ExpatError:  # cannot happen for a well-formed file; keep the plain reading
        root = _names_as_written(text, source)
    _drop_prefixed(root)
    return root


def _names_as_written(text: str, source: str) -> ET.Element:
    """The tree of well-formed ``text`` without namespace processing (``drake:joint`` stays so)."""
    builder = ET.TreeBuilder()
    parser = expat.ParserCreate()

    def refuse_doctype(*_args) -> None:
        raise UrdfShapeError(source, "XML with a DOCTYPE or entities is refused")

    parser.StartDoctypeDeclHandler = refuse_doctype
    parser.EntityDeclHandler = refuse_doctype
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.Parse(text, True)
    return builder.close()


def ignored_extensions(text: str, source: str, checked: bool = False) -> dict[str, int]:
    """{name as written: count} of the prefixed elements a URDF holds (``drake:rotor_inertia``),
    which urdfdom, and hence the model, leaves out; {} for a file without any (``checked``: as
    ``parse_xml_as_urdfdom_reads``)."""
    if "xmlns:" not in text:
        return {}
    if not checked:
        parse_xml(text, source)
    counts: dict[str, int] = {}
    stack = [_names_as_written(text, source)]
    while stack:
        element = stack.pop()
        for child in element:
            if ":" in child.tag:
                counts[child.tag] = counts.get(child.tag, 0) + 1
            else:
                stack.append(child)
    return dict(sorted(counts.items()))


def _drop_prefixed(element: ET.Element) -> None:
    """Remove what urdfdom never reads: prefixed elements and attributes, ``xmlns`` declarations."""
    for attr in [a for a in element.attrib if ":" in a or a == "xmlns"]:
        del element.attrib[attr]
    for child in list(element):
        if ":" in child.tag:
            element.remove(child)
        else:
            _drop_prefixed(child)
