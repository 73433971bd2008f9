"""What every figure of a report shares: an Agg figure with fixed margins, filled outlines,
legends and event names kept off the data, PNG bytes."""

from __future__ import annotations

import io

import numpy as np

__all__ = ["DPI", "_figure", "_fill", "_png", "_legend_below", "_event_ticks"]

#: Resolution of every figure: fine enough to print at the page's width (110 was too coarse).
DPI = 150


def _figure(width=7.5, height=5.0, **layout):
    """A figure and its axes; ``layout`` goes to ``plt.subplots`` (``nrows=2, sharex=True``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # constrained layout is solved at the one draw; tight_layout would draw the figure twice
    figure, axes = plt.subplots(figsize=(width, height), dpi=DPI, layout="constrained", **layout)
    return figure, axes


def _legend_below(figure, handles=None, labels=None, *, ncols=2, fontsize=8):
    """One legend for the whole figure, under the axes, so that it covers no data.

    ``handles``/``labels`` default to every labelled artist of every axes of the figure
    (twin axes included, each label once).
    """
    if handles is None:
        handles, labels, seen = [], [], set()
        for ax in figure.axes:
            for handle, label in zip(*ax.get_legend_handles_labels()):
                if label not in seen:
                    seen.add(label)
                    handles.append(handle)
                    labels.append(label)
    if handles:
        figure.legend(handles, labels, loc="outside lower center", ncols=ncols,
                      fontsize=fontsize, frameon=False)


def _event_ticks(ax, events: dict, *, fontsize=7, rotation=0):
    """Name events (``{name: x}``) on a second x axis above the plot, not on the curves."""
    top = ax.secondary_xaxis("top")
    names = list(events)
    top.set_xticks([events[name] for name in names], names)
    top.tick_params(labelsize=fontsize, length=3, pad=1)
    if rotation:
        for label in top.get_xticklabels():
            label.set_rotation(rotation)
            label.set_horizontalalignment("left")
    return top


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
    engine = figure.get_layout_engine()
    if engine is not None:
        # savefig draws a figure with a layout engine twice (a pre-draw that solves the layout,
        # then the draw); solving it here and dropping the engine draws it once, same pixels
        engine.execute(figure)
        figure.set_layout_engine(None)
    # no software/date metadata, so the same design gives the same bytes; light compression
    # (level 3 of 9) saves most of the encoding time for files a little larger
    figure.savefig(buffer, format="png", metadata={"Software": None},
                   pil_kwargs={"compress_level": 3})
    plt.close(figure)
    return buffer.getvalue()
