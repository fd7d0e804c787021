"""Reading a certificate file: bounded in size and nesting, every failure one line.

A certificate is read once, as bytes: ``recheck`` parses those bytes and, with
``--trust``, compares their SHA-256 with the signed statement, so what is checked is
what is parsed.  The file must be a regular file of at most ``MAX_CERTIFICATE_BYTES``;
its JSON may nest at most ``MAX_DEPTH`` levels (a certificate nests five) and may not
use the non-standard literals ``NaN``, ``Infinity`` and ``-Infinity`` (pendverify
writes a non-finite number as the string ``"inf"``, ``"-inf"`` or ``"nan"``).
"""

from __future__ import annotations

import json
import os
import re
import stat
from itertools import accumulate
from pathlib import Path

from pendverify.errors import CertificateError, missing_file

MAX_CERTIFICATE_BYTES = 16 * 1024 * 1024  # a certificate embeds its URDF and model text: far below this
MAX_DEPTH = 32


def read_limited(path: str | Path, limit: int, what: str, error=CertificateError) -> bytes:
    """At most ``limit`` bytes of the regular file ``path``; ``error`` (one line) otherwise."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        raise missing_file(path, what, "`pendverify certify ... -o DIR` writes a bundle into DIR") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory; give the {what} file") from None
    except OSError as exc:
        raise error(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    try:
        mode = os.fstat(fd).st_mode
        if stat.S_ISDIR(mode):
            raise error(f"{path}: is a directory; give the {what} file")
        if not stat.S_ISREG(mode):
            raise error(f"{path}: not a regular file; the {what} must be one")
        chunks, size = [], 0
        while size <= limit:  # a read may return less than asked
            chunk = os.read(fd, limit + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        data = b"".join(chunks)
    except OSError as exc:
        raise error(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise error(f"{path}: larger than the limit of {limit:,} bytes for a {what}")
    return data


def _refuse_constant(name: str):
    raise ValueError(f"the literal {name} is not JSON (pendverify writes a non-finite number as a string)")


_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
_BRACKET = re.compile(r"[\[\]{}]")


def nesting_depth(text: str) -> int:
    """How deep lists and objects nest in JSON text (brackets inside strings do not count)."""
    steps = (1 if b in "[{" else -1 for b in _BRACKET.findall(_STRING.sub("", text)))
    return max(accumulate(steps), default=0)


def parse_certificate(data: bytes, source: str):
    """The JSON value of a certificate file's bytes; CertificateError (one line) if it is not JSON
    or nests deeper than ``MAX_DEPTH``."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CertificateError(f"{source}: not UTF-8 text (byte {exc.start}: {exc.reason})") from None
    if nesting_depth(text) > MAX_DEPTH:  # bounded before the parser recurses into it
        raise CertificateError(
            f"{source}: JSON nested deeper than the limit of {MAX_DEPTH} levels "
            "(a certificate nests five); not a certificate"
        )
    try:
        return json.loads(text, parse_constant=_refuse_constant)
    except json.JSONDecodeError as exc:
        raise CertificateError(f"{source}: not JSON: {exc}") from None
    except (ValueError, RecursionError) as exc:  # a huge integer literal, a refused constant
        raise CertificateError(f"{source}: not a certificate's JSON: {exc}") from None


def read_certificate(path: str | Path) -> tuple[bytes, object]:
    """(the file's bytes, their JSON value): bounded, one line on any failure."""
    data = read_limited(path, MAX_CERTIFICATE_BYTES, "certificate (NAME.cert.json)")
    return data, parse_certificate(data, str(path))
