"""Pinocchio's URDF parser (urdfdom) run on text the strict reader accepted, its log captured.

``build_pinocchio_model`` runs these checks, then ``pinocchio.buildModelFromXML`` with
the C-level stderr (file descriptor 2) captured, so that a refusal names urdfdom's
reason and whatever urdfdom logs during a successful parse is handed back to the
caller instead of reaching the terminal.  The capture swaps the process-wide
descriptor 2; calls are serialised by a lock, but another thread writing to fd 2 at
the same moment is captured as well.

urdfdom parses the text itself (Pinocchio's bindings build a model from a URDF's text or
file only, not from a tree already parsed): that parse is the building of the model, the one
step that makes a ``PinocchioSystem``'s model, and the strict reader's tree
(``xml_reading.read_xml``) is the only parse pendverify does of the text.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import pinocchio as pin

from pendverify.errors import UrdfShapeError
from pendverify.robot.strict import DescriptionFacts, read_urdf_strictly
from pendverify.robot.xml_reading import XmlDocument


def build_pinocchio_model(
    text: str, source: str, document: XmlDocument | None = None
) -> tuple[pin.Model, DescriptionFacts, list[str]]:
    """Read ``text`` strictly, then build its Pinocchio model with urdfdom's log captured.

    Returns ``(model, facts, log)``: the model from ``pinocchio.buildModelFromXML``, the
    facts from ``read_urdf_strictly`` and the records urdfdom logged while parsing, one
    line each (often empty; e.g. "Error: Could not parse collision element for Link [l]"
    when a collision shape is one urdfdom does not know).  If Pinocchio refuses the
    text, ``UrdfShapeError`` carries urdfdom's reason instead of Pinocchio's generic
    "does not contain a valid URDF model".  ``document``: ``text`` as the caller has parsed it
    already (``xml_reading.read_xml``); None: parsed here.
    """
    facts = read_urdf_strictly(text, source, document)
    with _capture_fd2() as captured:
        try:
            model = pin.buildModelFromXML(text)
        except (RuntimeError, ValueError) as exc:
            failure: Exception | None = exc
        else:
            failure = None
    log = log_records(captured.text)
    if failure is not None:
        reason = "; ".join(_LEVEL.sub("", record) for record in log) or " ".join(str(failure).split())
        raise UrdfShapeError(source, f"Pinocchio cannot parse it as URDF: {reason}") from None
    return model, facts, log


_LEVEL = re.compile(r"^(Error|Warning|Info|Debug):\s*")


def log_records(text: str) -> list[str]:
    """urdfdom's stderr log as one line per record, without urdfdom's C++ source locations.

    console_bridge writes each record as ``"Error:   message"`` (or ``Warning:``, ...)
    followed by ``"         at line N in /path/file.cpp"``; the location names
    urdfdom's source, not the user's file, so it is dropped.
    """
    records: list[str] = []
    for line in text.splitlines():
        stripped = line.strip()
        if not stripped or re.fullmatch(r"at line \d+ in \S+", stripped):
            continue
        if _LEVEL.match(stripped) or not records:
            records.append(stripped)
        else:
            records[-1] += " " + stripped
    return [" ".join(r.split()) for r in records]


class _Captured:
    """The text written to the captured file descriptors inside a ``capture_output`` block (set on exit)."""

    text = ""


_FD2_LOCK = threading.Lock()


@contextmanager
def capture_output(fds: tuple[int, ...] = (2,)) -> Iterator[_Captured]:
    """Redirect file descriptors ``fds`` (2: C++ ``std::cerr``; 1: ``std::cout``) into one temporary file."""
    captured = _Captured()
    with _FD2_LOCK, tempfile.TemporaryFile() as tmp:
        sys.stdout.flush()
        sys.stderr.flush()
        saved = [os.dup(fd) for fd in fds]
        try:
            for fd in fds:
                os.dup2(tmp.fileno(), fd)
            yield captured
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            for fd, copy in zip(fds, saved, strict=True):
                os.dup2(copy, fd)
                os.close(copy)
            tmp.seek(0)
            captured.text = tmp.read().decode("utf-8", errors="replace")


def _capture_fd2():
    """``capture_output`` of file descriptor 2, where urdfdom's C++ ``std::cerr`` writes."""
    return capture_output((2,))


def build_from_file(builder, text: str, filename: str, source: str, kind: str):
    """``builder(path)`` on ``text`` written to a temporary ``filename`` (Pinocchio's Python
    bindings read MJCF and SDFormat from files only), its printed lines captured.

    Returns (what the builder built, the lines it printed); a failure is one ``UrdfShapeError``
    naming ``source`` and the last line of Pinocchio's message.
    """
    with tempfile.TemporaryDirectory(prefix="pendverify-") as folder:
        path = os.path.join(folder, filename)
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
        with capture_output((1, 2)) as captured:
            try:
                built = builder(path)
            except (RuntimeError, ValueError, IndexError) as exc:
                failure: Exception | None = exc
            else:
                failure = None
    if failure is not None:
        lines = [line.strip() for line in str(failure).splitlines() if line.strip()]
        reason = lines[-1] if lines else type(failure).__name__
        raise UrdfShapeError(
            source, f"Pinocchio cannot parse it as {kind}: {reason.removeprefix('message:').strip()}"
        )
    return built, log_records(captured.text)
