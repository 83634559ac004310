"""matplotlib figures rendered to inline SVG (Agg: no display, no network)."""
from __future__ import annotations

import io
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({
    # Text as text: a tenth of the size of glyph paths, searchable, and prints sharp.
    "svg.fonttype": "none",
    "font.size": 9,
    "figure.dpi": 100,
    "axes.grid": True,
    "grid.alpha": 0.3,
})

_PROLOGUE = re.compile(r"^.*?(?=<svg)", re.S)


def to_svg(fig, salt: str) -> str:
    """The figure as an <svg> element; ``salt`` keeps matplotlib's internal ids (clip paths, markers) unique
    and stable across the several figures inlined into one document."""
    buf = io.StringIO()
    with plt.rc_context({"svg.hashsalt": salt}):
        fig.savefig(buf, format="svg", bbox_inches="tight")
    plt.close(fig)
    svg = _PROLOGUE.sub("", buf.getvalue(), count=1)
    return svg.replace("<svg ", f'<svg role="img" aria-label="{salt}" ', 1)


def subplots(n: int = 1, *, ncols: int | None = None, width: float = 7.0, height: float = 3.2, **kw):
    ncols = ncols or n
    nrows = (n + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(width, height * nrows), squeeze=False, **kw)
    flat = list(axes.flat)
    for ax in flat[n:]:
        ax.set_visible(False)
    return fig, flat[:n]
