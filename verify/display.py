"""How pendverify's objects show themselves in a console or a notebook: short reprs, HTML tables.

A repr is one line of at most ``REPR_LIMIT`` characters (``shortened`` cuts a long path or
list in the middle); ``html_table`` is the table a notebook shows (``_repr_html_``), every
cell escaped.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence

#: the longest repr any public object gives
REPR_LIMIT = 300
#: inline style of a cell whose verdict is a failure (a notebook has no stylesheet of ours)
FAIL_STYLE = "color:#b00020;font-weight:bold"


def shortened(text: str, width: int) -> str:
    """``text`` itself when it has at most ``width`` characters, else its start and end around "…"."""
    if len(text) <= width:
        return text
    head = (width - 1) // 2
    return f"{text[:head]}…{text[len(text) - (width - 1 - head) :]}"


def listed(names: Iterable[str], width: int) -> str:
    """Names joined by ", ", shortened to ``width`` characters."""
    return shortened(", ".join(names), width)


def html_table(
    header: Sequence[str],
    rows: Iterable[Sequence[str]],
    caption: str | None = None,
    failing: Iterable[bool] | None = None,
) -> str:
    """An HTML table of text cells (escaped); a row whose ``failing`` flag is true shows in red."""
    flags = iter(failing) if failing is not None else None
    out = ["<table>"]
    if caption:
        out.append(f"<caption style='text-align:left'>{html.escape(caption)}</caption>")
    out.append("<thead><tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr></thead>")
    out.append("<tbody>")
    for row in rows:
        style = f" style='{FAIL_STYLE}'" if flags is not None and next(flags) else ""
        out.append(f"<tr{style}>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def html_fields(caption: str, fields: Iterable[tuple[str, object]]) -> str:
    """A two-column HTML table, field and value (escaped), under ``caption``: the notebook view of
    a result that is one record rather than rows."""
    return html_table(("", ""), [(name, str(value)) for name, value in fields], caption)


def html_text(text: str) -> str:
    """A report printed as text (the command's own table), as preformatted HTML."""
    return f"<pre>{html.escape(text)}</pre>"


def html_lines(lines: Iterable[str]) -> str:
    """Lines of text as escaped paragraphs-in-a-list (notes, warnings, a verdict)."""
    items = "".join(f"<li>{html.escape(line)}</li>" for line in lines)
    return f"<ul style='list-style:none;padding-left:0'>{items}</ul>" if items else ""
