"""Expand a xacro file into URDF with the ``xacro`` package (pure Python; no ROS needed).

Conventions:

* The file is first read as XML with the strict reader's rules (``pendverify.robot.xml_reading.parse_xml``:
  no DOCTYPE, no entities); xacro then processes that document as ``xacro FILE`` would, with
  no ``name:=value`` mappings: every ``xacro:arg`` takes the default the file gives it (an
  argument without a default is xacro's own error).  Includes are resolved relative to the
  file (relative to the working directory for XML text given directly).
* ``$(find PKG)`` needs ROS's package index (``ament_index_python``); without it the file is
  refused with a one-line error saying so (expand it in a ROS environment and give the URDF).
* Whatever xacro prints (its warnings) is captured and handed back as log lines.
* Every xacro error is one ``UrdfShapeError`` naming the xacro file (and the included file the
  error arose in), never a traceback.

xacro keeps its state in module globals, so expansions are serialised by a lock.
"""

from __future__ import annotations

import contextlib
import io
import threading
import xml.dom.minidom
from pathlib import Path

from pendverify.display import shortened
from pendverify.errors import UrdfShapeError
from pendverify.robot.xml_reading import parse_xml

#: namespace URIs that mark an element or attribute as xacro's (ElementTree spells them {uri}tag)
XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "http://wiki.ros.org/xacro")
#: file names that are xacro whatever they contain
XACRO_SUFFIXES = (".xacro",)

_LOCK = threading.Lock()
#: characters of xacro's message quoted (it may hold a whole ${...} expression)
REASON_WIDTH = 200


def uses_xacro(root) -> bool:
    """Whether an ElementTree document has an element or attribute in xacro's namespace."""
    marks = tuple("{" + uri + "}" for uri in XACRO_NAMESPACES)
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.startswith(marks):
            return True
        if any(name.startswith(marks) for name in element.attrib):
            return True
    return False


def expand_xacro(text: str, path: Path | None, source: str) -> tuple[str, list[str]]:
    """(URDF text, xacro's log lines) of the xacro document ``text`` read from ``path`` (None: text given).

    Raises ``UrdfShapeError(source, ...)`` for XML the strict reader refuses and for every
    error xacro reports.
    """
    parse_xml(text, source)  # DOCTYPE/entities and malformed XML are refused with the strict reader's words
    try:
        import xacro
    except ImportError:  # pragma: no cover - a dependency of pendverify
        raise UrdfShapeError(source, "a xacro file, but the 'xacro' package is not installed") from None
    printed = io.StringIO()
    with _LOCK:
        try:
            with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
                xacro.init_stacks(None if path is None else str(path))
                xacro.all_includes = []
                doc = xml.dom.minidom.parseString(text)
                xacro.process_doc(doc)
        except Exception as exc:  # xacro's errors, including the evaluation of ${...} expressions
            where = _included_file(xacro, path)
            raise UrdfShapeError(source, f"xacro cannot expand it{where}: {_reason(exc)}") from None
        finally:
            xacro.init_stacks(None)
    origin = "XML text" if path is None else Path(path).name
    doc.insertBefore(
        doc.createComment(f" expanded by xacro from {origin} (its xacro:arg defaults) "), doc.firstChild
    )
    expanded = doc.toprettyxml(indent="  ")
    log = [" ".join(line.split()) for line in printed.getvalue().splitlines() if line.strip()]
    return expanded, log


def _included_file(xacro, path: Path | None) -> str:
    """ ", in included file F" when xacro's error arose in a file other than the one given."""
    stack = [f for f in (xacro.filestack or []) if f]
    if stack and (path is None or Path(stack[-1]).resolve() != Path(path).resolve()):
        return f" (in included file {stack[-1]})"
    return ""


def _reason(exc: Exception) -> str:
    message = " ".join(str(exc).split()) or type(exc).__name__
    if "ament_index_python" in message:
        return (
            "it uses $(find PKG), which needs ROS's package index (ament_index_python), not installed here: "
            "expand it in a ROS environment (xacro FILE > FILE.urdf) and give the URDF"
        )
    return shortened(message, REASON_WIDTH)
