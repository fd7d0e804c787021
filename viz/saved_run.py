"""The arrays of a saved run (the npz of ``pendverify simulate -o``), bounded before any is loaded.

An npz is a zip of ``.npy`` files, and a compressed member of a few kB can declare an array of
many GiB.  ``read_saved_arrays`` therefore reads each member's ``.npy`` header first (shape and
dtype, nothing else) and refuses, with one ``TrajectoryError`` naming the array and the limit:

* a member that is missing, or whose header is not a ``.npy`` header;
* ``t`` or ``q`` that is not real numbers (bool, int or float: no objects, strings, complex);
* ``t`` with more samples than ``PENDVERIFY_MAX_SAMPLES`` (the limit a scene's output samples
  have, ``pendverify.simulation.limits``), ``q`` with more than ``MAX_COORDINATES`` numbers per
  sample of that limit;
* ``metadata`` that is not one text string of at most ``MAX_METADATA_BYTES``.

Only then is each array loaded (``allow_pickle=False``); the metadata is parsed as JSON, a
nesting too deep for the parser refused like any other malformed JSON.
"""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np

from pendverify.display import shortened
from pendverify.errors import TrajectoryError
from pendverify.simulation.limits import MAX_SAMPLES_VARIABLE, max_samples

#: numbers per sample ``q`` may hold (coordinates of the largest model), times the sample limit
MAX_COORDINATES = 64
#: bytes of the metadata string (it holds the parameters and a URDF's path)
MAX_METADATA_BYTES = 16 * 2**20
NUMERIC_KINDS = "biuf"
#: characters of a reader's reason quoted in a message
REASON_WIDTH = 120


def read_saved_arrays(path: Path, source: str) -> tuple[np.ndarray, np.ndarray, object]:
    """(t, q, the metadata's JSON value) of a saved run, each bounded (see the module docstring)."""
    limit = max_samples()
    bounds = {"t": limit, "q": limit * MAX_COORDINATES}
    try:
        with zipfile.ZipFile(path) as archive:
            headers = {name: _header(archive, name, source) for name in ("t", "q", "metadata")}
    except (zipfile.BadZipFile, OSError, EOFError, ValueError) as exc:  # zip reading errors only
        raise TrajectoryError(source, "<file>", source, f"not a pendverify npz: {_reason(exc)}") from None
    for name, bound in bounds.items():
        shape, dtype = headers[name]
        if dtype.kind not in NUMERIC_KINDS:
            raise TrajectoryError(source, name, str(dtype), "must be an array of real numbers")
        size = int(np.prod(shape, dtype=object))
        if size > bound:
            per = "" if name == "t" else f" × {MAX_COORDINATES} coordinates"
            raise TrajectoryError(
                source,
                name,
                shape,
                f"{size:.3g} numbers exceed the limit of {limit:g} samples{per}; "
                f"raise the limit with {MAX_SAMPLES_VARIABLE}",
            )
    shape, dtype = headers["metadata"]
    if dtype.kind not in "US" or int(np.prod(shape, dtype=object)) != 1:
        raise TrajectoryError(source, "metadata", f"{dtype} {shape}", "must be one JSON string")
    if dtype.itemsize > MAX_METADATA_BYTES:
        raise TrajectoryError(
            source, "metadata", f"{dtype.itemsize} bytes", f"exceeds the limit of {MAX_METADATA_BYTES} bytes"
        )
    try:
        with np.load(path, allow_pickle=False) as npz:
            t, q, text = npz["t"], npz["q"], npz["metadata"].reshape(()).item()
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise TrajectoryError(source, "<file>", source, f"not a pendverify npz: {_reason(exc)}") from None
    return t, q, _metadata(text, source)


def _header(archive: zipfile.ZipFile, name: str, source: str) -> tuple[tuple[int, ...], np.dtype]:
    """(shape, dtype) from the ``.npy`` header of member ``name``, nothing more read."""
    try:
        member = archive.open(f"{name}.npy")
    except KeyError:
        raise TrajectoryError(source, name, None, "missing array in the npz") from None
    with member:
        try:
            version = np.lib.format.read_magic(member)
            if version == (1, 0):
                shape, _, dtype = np.lib.format.read_array_header_1_0(member)
            elif version in ((2, 0), (3, 0)):
                shape, _, dtype = np.lib.format.read_array_header_2_0(member)
            else:
                raise ValueError(f"npy format version {version}")
        except (ValueError, SyntaxError, TypeError) as exc:
            raise TrajectoryError(source, name, None, f"not a .npy array: {_reason(exc)}") from None
    return shape, dtype


def _metadata(text: object, source: str) -> object:
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise TrajectoryError(source, "metadata", f"byte {exc.start}", "must be UTF-8 text") from None
    try:
        return json.loads(str(text))
    except ValueError as exc:
        raise TrajectoryError(source, "metadata", None, f"not JSON: {_reason(exc)}") from None
    except RecursionError:
        raise TrajectoryError(source, "metadata", None, "not JSON: nested too deeply") from None


def _reason(exc: BaseException) -> str:
    return shortened(" ".join(str(exc).split()) or type(exc).__name__, REASON_WIDTH)
