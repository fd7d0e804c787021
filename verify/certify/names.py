"""Names are not paths: the one rule for the names a bundle's files are made of.

A set's name (``set_name``: for a set certified on a URDF, its model's name and the URDF's)
becomes ``DIR/NAME.cert.json``, ``NAME.urdf``, ``NAME.params.toml``,
``NAME.model.py`` and ``NAME.intoto.jsonl``.  Wherever a name is read (a parameter
file's ``name``, a URDF's stem, a sweep's set names, a certificate's ``name`` and
the envelope it names), it must match ``NAME_PATTERN``: a letter or digit, then up
to 127 letters, digits, ``.``, ``_`` or ``-``, not ending in ``.``.  That excludes
``..``, ``/`` and ``\\``, drive letters (``C:``), absolute paths, empty names,
newlines and NUL.  As a second line of defence every bundle write resolves its
target (symbolic links included) and refuses anything that is not directly inside
the resolved output folder (``target_inside``).
"""

from __future__ import annotations

import re
from pathlib import Path

from pendverify.errors import BundleNameError, CertificateError

NAME_PATTERN = r"[A-Za-z0-9][A-Za-z0-9._-]{0,127}"
NAME_RULE = (
    f"a bundle name must match {NAME_PATTERN} and not end in '.' "
    "(it names files in the output folder, so no path, separator or control character)"
)
_NAME = re.compile(NAME_PATTERN)


def check_name(value: object, source: str, key: str) -> str:
    """``value`` if it is a valid bundle name, else a BundleNameError naming source, key, value and rule."""
    if not isinstance(value, str) or not _NAME.fullmatch(value) or value.endswith("."):
        raise BundleNameError(source, key, value, NAME_RULE)
    return value


def set_name(model: str, urdf_name: str, source: str) -> str:
    """The name of a set certified on a URDF: its model's name, then the URDF's (its stem, or
    ``erd_<stem>``) when that is another name — ``double_pendulum-bench_rig`` for the double
    pendulum on ``bench_rig.urdf``, ``double_pendulum-erd_double_pendulum`` on
    example-robot-data's — so one model certified on two URDFs into one folder gets two bundles.
    A URDF whose name starts with the model's (``cart_pole.urdf``, ``cart_pole_heavy.urdf``, a
    sweep's ``cart_pole-3.urdf``) names the set alone: it names the model already, and a set a
    sweep certified keeps its name when certified again from its bundle's files.  Checked as
    every name is.

    (Certificates issued before this rule are named by the URDF alone; recheck reads the name a
    certificate records, so they are read as they are.)"""
    names_the_model = urdf_name == model or urdf_name.startswith((f"{model}-", f"{model}_", f"{model}."))
    name = urdf_name if names_the_model else f"{model}-{urdf_name}"
    return check_name(name, source, "bundle name (the model's name, then the URDF's)")


def target_inside(directory: str | Path, path: str | Path) -> Path:
    """``path`` resolved, if it lies directly in the resolved ``directory``; else a CertificateError.

    Symbolic links are followed on both sides, so a link planted at ``DIR/NAME.cert.json``
    that points elsewhere is refused, as is any name that climbs out of the folder.
    """
    folder = Path(directory).resolve()
    target = Path(path).resolve()
    if target.parent != folder:
        raise CertificateError(
            f"{path}: refused: it resolves to {target}, outside the output folder {folder} "
            "(a bundle file is written only directly inside it)"
        )
    return target


def envelope_name(name: str) -> str:
    """The file a signed certificate's DSSE envelope is written to, beside it."""
    return f"{name}.intoto.jsonl"
