"""Expand a xacro file into URDF with the ``xacro`` package (pure Python; no ROS needed).

Conventions:

* The file is first read as XML with the strict reader's rules (``pendverify.robot.xml_reading.read_xml``:
  no DOCTYPE, no entities); xacro then processes that document as ``xacro FILE`` would, with
  no ``name:=value`` mappings: every ``xacro:arg`` takes the default the file gives it (an
  argument without a default is xacro's own error).  Includes are resolved relative to the
  file (relative to the working directory for XML text given directly).
* ``$(find PKG)`` is package PKG's folder as ``pendverify.robot.packages.find_package`` finds it
  (``--package-path``, ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``), not ROS's package index; an
  include's ``package://PKG/...`` file name is resolved the same way.  xacro's seams for this are
  two module-level functions it looks up at each call: ``xacro.substitution_args._eval_find``
  (what ``$(find)`` evaluates to) and ``xacro.abs_filename_spec`` (an include's file name made
  absolute).  They are replaced for the duration of one expansion, under the lock that already
  serialises expansions, and restored afterwards; an unknown package is one line naming it and
  the folders searched.
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
from pendverify.robot.packages import PACKAGE_SCHEME, resolve_uri
from pendverify.robot.xml_reading import XmlDocument, read_xml

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


def expand_xacro(
    text: str, path: Path | None, source: str, document: XmlDocument | None = None
) -> tuple[str, list[str]]:
    """(URDF text, xacro's log lines) of the xacro document ``text`` read from ``path`` (None: text given).

    Raises ``UrdfShapeError(source, ...)`` for XML the strict reader refuses and for every
    error xacro reports.  ``document``: ``text`` as the caller has parsed it already (None: parsed here).
    """
    if document is None:  # DOCTYPE/entities and malformed XML are refused with the strict reader's words
        read_xml(text, source)
    try:
        import xacro
    except ImportError:  # pragma: no cover - a dependency of pendverify
        raise UrdfShapeError(source, "a xacro file, but the 'xacro' package is not installed") from None
    from xacro import substitution_args

    printed = io.StringIO()
    with _LOCK:
        xacro_find, xacro_filename = substitution_args._eval_find, xacro.abs_filename_spec

        def find(name: str) -> str:
            return resolve_uri(f"{PACKAGE_SCHEME}{name}", source).rstrip("/")

        def filename(spec: str) -> str:
            return resolve_uri(spec, source) if spec.startswith(PACKAGE_SCHEME) else xacro_filename(spec)

        try:
            substitution_args._eval_find, xacro.abs_filename_spec = find, filename
            with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
                xacro.init_stacks(None if path is None else str(path))
                xacro.all_includes = []
                doc = xml.dom.minidom.parseString(text)
                xacro.process_doc(doc)
        except Exception as exc:  # xacro's errors, including the evaluation of ${...} expressions
            where = _included_file(xacro, path)
            package = _package_error(exc)  # a package not found: its own sentence, whole
            reason = _reason(exc) if package is None else package.problem
            raise UrdfShapeError(source, f"xacro cannot expand it{where}: {reason}") from None
        finally:
            substitution_args._eval_find, xacro.abs_filename_spec = xacro_find, xacro_filename
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


def _package_error(exc: BaseException | None) -> UrdfShapeError | None:
    """The ``UrdfShapeError`` of an unknown package that xacro wrapped (in ``XacroException.exc``)."""
    seen = 0
    while exc is not None and seen < 20:
        if isinstance(exc, UrdfShapeError):
            return exc
        exc, seen = getattr(exc, "exc", None) or exc.__cause__ or exc.__context__, seen + 1
    return None


def _reason(exc: Exception) -> str:
    message = " ".join(str(exc).split()) or type(exc).__name__
    return shortened(message, REASON_WIDTH)
