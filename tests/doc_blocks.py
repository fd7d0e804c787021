"""The shell blocks of the README and the manual, read as a newcomer reads them, and their outputs compared.

A page is a sequence of steps, in its order:

* a code block with a title (```` ```python title="my_pendulum.py" ````) is a file the reader
  saves: it is written into the folder under that name;
* a ```` ```sh ```` block is commands, run as one ``bash`` script (``set -e``: it stops at the
  first command that fails, and its status is that command's); the plain ```` ``` ```` block
  right after it, when there is one, is what it prints;
* a ```` ```console ```` block is ``$ COMMAND`` lines, each followed by what it prints.

``same_output`` compares a printed text with the manual's; the rules are in its docstring.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

#: a fenced block: its info string (language, then attributes) and its text
FENCE = re.compile(r"^```(?P<info>[^\n`]*)\n(?P<body>.*?)^```[ \t]*$", re.S | re.M)
TITLE = re.compile(r'\btitle="(?P<title>[^"]+)"')
#: a line of the manual's output that stands for any number of lines left out
ELISION = "..."
#: a number that is a figure of its own: not part of a name (``theta2``, ``q1``) or a path
NUMBER = re.compile(r"(?<![\w.])[-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w.]*\w)")
#: a number followed by its unit of time: a wall time
TIMING = re.compile(r"\s?(?:s|ms)(?!\w)")


@dataclass(frozen=True)
class Step:
    """One thing a reader does, at ``line`` of ``page``: save ``text`` as ``file``, or run ``text``."""

    page: str
    line: int
    text: str
    #: the name a titled block is saved as (None: a step that runs commands)
    file: str | None = None
    #: what the manual says the commands print (None: it does not say)
    output: str | None = None

    @property
    def key(self) -> tuple[str, str]:
        """(page, the step's first line): how the tables of the test name it."""
        return self.page, self.text.splitlines()[0].strip()


def steps(text: str, page: str) -> list[Step]:
    """The steps of a page whose text is ``text`` (``page``: its path, for messages and keys)."""
    found: list[Step] = []
    fences = list(FENCE.finditer(text))
    used_as_output: set[int] = set()
    for k, fence in enumerate(fences):
        if k in used_as_output:
            continue
        info, body = fence["info"].strip(), fence["body"]
        language = info.split()[0] if info else ""
        line = text.count("\n", 0, fence.start()) + 1
        title = TITLE.search(info)
        if title:
            found.append(Step(page, line, body, file=title["title"]))
        elif language == "sh":
            output = None
            if k + 1 < len(fences) and not fences[k + 1]["info"].strip():
                between = text[fence.end() : fences[k + 1].start()]
                if not between.strip():
                    output = fences[k + 1]["body"]
                    used_as_output.add(k + 1)
            found.append(Step(page, line, body, output=output))
        elif language == "console":
            found += _console_steps(body, page, line)
    return found


def _console_steps(body: str, page: str, line: int) -> list[Step]:
    """Each ``$ COMMAND`` line of a console block, with the lines up to the next one as its output."""
    found: list[Step] = []
    for k, row in enumerate(body.splitlines(keepends=True)):
        if row.startswith("$ "):
            found.append(Step(page, line + 1 + k, row[2:], output=""))
        elif found:
            found[-1] = Step(page, found[-1].line, found[-1].text, output=found[-1].output + row)
    return found


# --- comparing outputs ------------------------------------------------------------------------------
#: below this size a printed figure is an error or a tolerance at the scale of rounding
#: (pendverify's errors are relative, its tolerances K·ε·(…) with ε = 2.2e-16): see same_number
ROUNDING_SCALE = 1e-9
#: the relative difference allowed between two figures above the rounding scale: 2 significant digits
RELATIVE = 1e-2


def _float(token: str) -> float:
    return float(token.replace("−", "-"))


def same_number(expected: str, actual: str) -> bool:
    """Whether a printed figure is the manual's, as far as the machine can reproduce it.

    * An integer (no point, no exponent: a count, an index, a seed) is exact.
    * A figure below ``ROUNDING_SCALE`` is an error or a tolerance on the scale of rounding.
      An error figure is a sum of roundings, each at most ε/2 of a term, whose value depends on
      the order of the operations (SIMD width, fused multiply-adds, the libm's sin and cos),
      which differs between machines and builds: only its order of magnitude is reproducible.
      Two such figures agree when both are zero, or both have the same sign and are within a
      factor of 10 (``|log10(a/b)| ≤ 1``).
    * Any other figure (a state, a failing check's error, a parameter) is a few operations on
      the seeded states, reproducible to ~1e-15 relative and printed to 3 or more significant
      digits; the last printed digit may still flip at a rounding boundary, so two such figures
      agree to 2 significant digits: ``|a − b| ≤ RELATIVE · max(|a|, |b|)``.
    """
    if not any(c in expected + actual for c in ".e"):
        return expected.replace("−", "-").lstrip("+") == actual.replace("−", "-").lstrip("+")
    a, b = _float(expected), _float(actual)
    if math.isnan(a) or math.isnan(b):
        return False
    if min(abs(a), abs(b)) < ROUNDING_SCALE or max(abs(a), abs(b)) < ROUNDING_SCALE:
        if a == 0 or b == 0:
            return a == b
        return (a > 0) == (b > 0) and abs(math.log10(abs(a) / abs(b))) <= 1
    return abs(a - b) <= RELATIVE * max(abs(a), abs(b))


def _parts(line: str) -> list[tuple[str, str]]:
    """A line as ("text", words) and ("number", figure) and ("time", figure) parts, in order."""
    parts, end = [], 0
    for m in NUMBER.finditer(line):
        parts.append(("text", line[end : m.start()]))
        timed = TIMING.match(line, m.end())
        parts.append(("time" if timed else "number", m.group()))
        end = m.end()
    parts.append(("text", line[end:]))
    return parts


def line_difference(expected: str, actual: str) -> str | None:
    """None if ``actual`` is the manual's line ``expected`` (``same_number`` for figures, wall
    times free, the rest verbatim but for trailing spaces); else what differs."""
    want, got = _parts(expected.rstrip()), _parts(actual.rstrip())
    if [kind for kind, _ in want] != [kind for kind, _ in got]:
        return "the words differ"
    for (kind, w), (_, g) in zip(want, got, strict=True):
        if kind == "text" and w != g:
            return f"{w!r} is {g!r}"
        if kind == "number" and not same_number(w, g):
            return f"the figure {w} is {g}"
    return None


def output_difference(expected: str, actual: str) -> str | None:
    """None if ``actual`` is the manual's output ``expected``, line by line (``line_difference``); a
    line ``...`` in ``expected`` stands for any lines, none included.  Else the first difference."""
    want, got = expected.rstrip("\n").splitlines(), actual.rstrip("\n").splitlines()
    segments: list[list[str]] = [[]]
    for row in want:
        if row.strip() == ELISION:
            segments.append([])
        else:
            segments[-1].append(row)
    at = 0
    for k, segment in enumerate(segments):
        first, last = k == 0, k == len(segments) - 1
        if last and not first:  # the last segment sits at the end
            start = len(got) - len(segment)
            if start < at:
                return f"the output has {len(got)} lines, too few for the manual's"
            at = start
        elif not first:  # the first place after an elision where the segment holds
            at = next((s for s in range(at, len(got) - len(segment) + 1) if _holds(segment, got[s:])), None)
            if at is None:
                return f"no lines after an elision match the manual's {segment[0]!r}"
        for n, row in enumerate(segment):
            if at + n >= len(got):
                return f"the manual's line {row!r} is missing (the output has {len(got)} lines)"
            why = line_difference(row, got[at + n])
            if why:
                return f"line {at + n + 1}: {why}\n  manual: {row}\n  output: {got[at + n]}"
        at += len(segment)
        if last and at != len(got):
            return f"the output goes on after the manual's last line: {got[at]!r}"
    return None


def _holds(segment: list[str], rows: list[str]) -> bool:
    return len(rows) >= len(segment) and all(
        line_difference(w, g) is None for w, g in zip(segment, rows, strict=False)
    )


def page_name(path: Path, root: Path) -> str:
    return path.relative_to(root).as_posix()
