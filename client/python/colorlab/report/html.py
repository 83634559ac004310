"""HTML pieces of the report: tables whose cells carry their exact numbers, figures holding inline SVG.

Every number cell has ``data-value`` (repr of the float, full precision) and ``data-row``/``data-col``, and every
table an ``id``, so a reader (or a test) takes the numbers from the markup instead of re-parsing rounded text.
"""
from __future__ import annotations

import html
import math
import re

CSS = """
body { font: 14px/1.45 "DejaVu Sans", Helvetica, Arial, sans-serif; margin: 2em auto; max-width: 1100px; color: #111; padding: 0 1em; }
h1 { font-size: 1.6em; } h2 { font-size: 1.3em; border-bottom: 1px solid #999; margin-top: 2em; } h3 { font-size: 1.1em; }
table { border-collapse: collapse; margin: .6em 0 1.2em; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #bbb; padding: 2px 6px; text-align: right; }
th { background: #eee; } td.label, th.label { text-align: left; }
tr.published td { color: #444; } tr.diff td { font-style: italic; }
td.na { color: #999; } td.best { font-weight: bold; background: #e8f4e8; }
caption { caption-side: top; text-align: left; font-weight: bold; padding-bottom: .3em; }
figure { margin: 1em 0; page-break-inside: avoid; break-inside: avoid; }
figure svg { max-width: 100%; height: auto; display: block; }
figcaption { font-size: .92em; color: #333; }
.note { color: #444; font-size: .92em; } .warn { color: #8a3b00; }
.simulated { border: 2px solid #c60; padding: .4em .8em; background: #fff6ec; }
.section-table { overflow-x: auto; }
@media print {
  body { margin: 0; max-width: none; font-size: 10pt; }
  h2 { page-break-before: always; break-before: page; } h2.first { page-break-before: avoid; break-before: avoid; }
  table, figure { page-break-inside: avoid; break-inside: avoid; }
  .section-table { overflow: visible; }
  table { font-size: 7.5pt; } th, td { padding: 1px 3px; }
  a { color: inherit; text-decoration: none; }
}
"""


def esc(text) -> str:
    return html.escape(str(text), quote=True)


def fmt(value, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    if isinstance(value, (int,)) and not isinstance(value, bool):
        return str(value)
    return f"{value:.{digits}f}"


def slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_-]+", "-", str(text)).strip("-")


def cell(value, *, row: str, col: str, kind: str = "", digits: int = 2, css: str = "") -> str:
    """A number cell; None shows as a dash (no published value, or illegible in the text)."""
    classes = " ".join(c for c in (css, "na" if value is None else "") if c)
    attrs = f' data-row="{esc(row)}" data-col="{esc(col)}"'
    if kind:
        attrs += f' data-kind="{esc(kind)}"'
    if value is not None:
        attrs += f' data-value="{esc(repr(float(value)))}"'
    if classes:
        attrs += f' class="{classes}"'
    return f"<td{attrs}>{esc(fmt(value, digits))}</td>"


def table(table_id: str, caption: str, columns, rows, *, corner: str = "", note: str = "") -> str:
    """rows: (label, [values], kind, row_key, css per value or None) tuples; kind names the row's meaning
    (measured, published, difference, …) and becomes the row's class and each cell's data-kind."""
    out = [f'<div class="section-table"><table id="{esc(table_id)}"><caption>{esc(caption)}</caption>',
           "<thead><tr>" + f'<th class="label">{esc(corner)}</th>' + "".join(f"<th>{esc(c)}</th>" for c in columns)
           + "</tr></thead><tbody>"]
    for label, values, kind, key, *rest in rows:
        styles = rest[0] if rest and rest[0] else [""] * len(values)
        digits = rest[1] if len(rest) > 1 else 2
        out.append(f'<tr class="{esc(kind)}" data-row="{esc(key)}"><td class="label">{esc(label)}</td>'
                   + "".join(cell(v, row=key, col=str(c), kind=kind, css=s, digits=digits)
                             for v, c, s in zip(values, columns, styles)) + "</tr>")
    out.append("</tbody></table></div>")
    if note:
        out.append(f'<p class="note">{note}</p>')
    return "\n".join(out)


def difference(measured, published):
    return [None if m is None or p is None else m - p for m, p in zip(measured, published)]


def figure(fig_id: str, svg: str, caption: str, item: str = "") -> str:
    data = f' data-figure="{esc(item)}"' if item else ""
    return f'<figure id="{esc(fig_id)}"{data}>{svg}<figcaption>{caption}</figcaption></figure>'


def document(title: str, body: str) -> str:
    # An empty icon: served by the daemon, the file would otherwise make the browser ask its origin for /favicon.ico.
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><link rel=\"icon\" href=\"data:,\">"
            f"<title>{esc(title)}</title><style>{CSS}</style></head><body>\n{body}\n</body></html>\n")
