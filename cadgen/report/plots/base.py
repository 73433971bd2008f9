"""What every figure of a report shares: an Agg figure with fixed margins, filled outlines, PNG bytes."""

from __future__ import annotations

import io

import numpy as np

__all__ = ["_figure", "_fill", "_png"]


def _figure(width=7.5, height=5.0, **layout):
    """A figure and its axes; ``layout`` goes to ``plt.subplots`` (``nrows=2, sharex=True``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # constrained layout is solved at the one draw; tight_layout would draw the figure twice
    figure, axes = plt.subplots(figsize=(width, height), dpi=110, layout="constrained", **layout)
    return figure, axes


def _fill(ax, x, y, **style):
    """A filled polygon, fast for outlines of thousands of points.

    ``Axes.fill`` makes a patch whose data limits matplotlib finds by walking every
    segment in Python (seconds for a gear outline); a PolyCollection with the
    limits given directly draws the same thing.
    """
    from matplotlib.collections import PolyCollection

    xy = np.column_stack([np.asarray(x, dtype=float), np.asarray(y, dtype=float)])
    colour = style.pop("color", None)
    if colour is not None:
        style.setdefault("facecolor", colour)
    edge = style.pop("ec", None)
    if edge is not None:
        style["edgecolor"] = edge
    width = style.pop("lw", None)
    if width is not None:
        style["linewidth"] = width
    if "facecolor" not in style:
        style["facecolor"] = ax._get_lines.get_next_color()
    collection = PolyCollection([xy], **style)
    ax.add_collection(collection)
    ax.update_datalim(xy)
    ax.autoscale_view()
    return collection


def _png(figure) -> bytes:
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    # no software/date metadata, so the same design gives the same bytes; light compression
    # (level 3 of 9) saves most of the encoding time for files a little larger
    figure.savefig(buffer, format="png", metadata={"Software": None},
                   pil_kwargs={"compress_level": 3})
    plt.close(figure)
    return buffer.getvalue()
