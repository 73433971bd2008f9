"""What every figure of a report shares: an Agg figure laid out by measured margins, filled
outlines, legends and event names kept off the data, PNG bytes."""

from __future__ import annotations

import functools
import struct
import zlib

import numpy as np

__all__ = ["DPI", "_figure", "_fill", "_add_patch", "_png", "_encode_png", "_legend_below",
           "_event_ticks", "_suptitle"]

#: Resolution of every figure: fine enough to print at the page's width (110 was too coarse).
DPI = 150
#: zlib level of the PNG files. Level 6 makes the report's sixteen figures 12 % smaller (1.56
#: against 1.78 MB, both below the 1.92 MB Pillow's level 3 wrote) for twice the encoding time
#: (0.15 against 0.07 s); the report is opened locally, the build is waited for.
PNG_COMPRESSION = 3


def _figure(width=7.5, height=5.0, **grid):
    """A figure and its axes; ``grid`` goes to ``Figure.subplots`` (``nrows=2, sharex=True``).

    ``height`` is the figure's height, or its ceiling when every axes has an equal aspect
    (see :func:`cadgen.report.plots.layout.fit_layout`, run by :func:`_png`). The figure is
    not registered with pyplot: nothing global to create or close.
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=DPI)
    _canvas_class()(figure)
    return figure, figure.subplots(**grid)


@functools.lru_cache(maxsize=1)
def _canvas_class():
    """An Agg canvas whose renderer measures texts through one cache for every figure.

    matplotlib caches a text's size per renderer, and each figure has its own: the tick
    labels, axis labels and legend entries the figures share ("0", "x (mm)") were measured
    again for each (FreeType lays the string out). The pixels are Agg's.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg

    class Renderer(RendererAgg):
        def get_text_width_height_descent(self, s, prop, ismath):
            if ismath:
                return super().get_text_width_height_descent(s, prop, ismath)
            import matplotlib as mpl

            # what the measure depends on: the string, the font, the resolution, the hinting
            # (a FontProperties hashes by its current values: a copy is kept as the key)
            key = (s, prop.copy(), self.dpi, mpl.rcParams["text.hinting"],
                   mpl.rcParams["text.hinting_factor"])
            found = _TEXT_SIZES.get(key)
            if found is None:
                found = super().get_text_width_height_descent(s, prop, ismath)
                if len(_TEXT_SIZES) >= 4096:
                    _TEXT_SIZES.clear()
                _TEXT_SIZES[key] = found
            return found

    class Canvas(FigureCanvasAgg):
        def get_renderer(self):
            w, h = self.get_width_height(physical=True)
            key = w, h, self.figure.dpi
            if getattr(self, "_cadgen_key", None) != key:
                self.renderer = Renderer(w, h, self.figure.dpi)
                self._cadgen_key = key
            return self.renderer

    return Canvas


#: ``(string, font, dpi, hinting...) -> (width, height, descent)`` of the texts drawn.
_TEXT_SIZES: dict = {}


def _suptitle(figure, text: str, *, fontsize=12):
    """A title over the whole grid (the layout keeps room for it above the axes' titles)."""
    return figure.text(0.5, 1.0, text, ha="center", va="top", fontsize=fontsize)


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
        from cadgen.report.plots.legend import foot_legend

        # at the figure's foot; the layout keeps the room for it under the axes
        foot_legend(figure, handles, labels, ncols=ncols, fontsize=fontsize, dpi=DPI)


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


#: Settings the figures are laid out and drawn with. Text is most of a figure's drawing, and
#: FreeType's hinting most of a glyph's cost: unhinted glyphs are drawn a quarter faster and
#: look the same at 150 dpi.
_DRAWING = {"text.hinting": "no_hinting"}


def _add_patch(ax, patch, low, high):
    """Add a patch whose data extent (``low``, ``high`` corners) is known.

    ``Axes.add_patch`` finds a patch's extent by walking its Bezier segments in Python (about
    half a millisecond a circle); a drawing of dozens of holes and seats gives it instead.
    """
    ax.add_artist(patch)
    ax.update_datalim([low, high])
    return patch


def _png(figure) -> bytes:
    """Lay the figure out, draw it once and return it as PNG bytes (the same for the same
    figure: no date or software in the file)."""
    import matplotlib

    from cadgen.report.plots.layout import fit_layout
    from cadgen.report.plots.ticks import batch_ticks

    with matplotlib.rc_context(_DRAWING):
        fit_layout(figure, dpi=DPI)
        batch_ticks(figure)
        figure.canvas.draw()
    rgba = np.asarray(figure.canvas.buffer_rgba())
    return _encode_png(rgba[:, :, :3], dpi=DPI)


def _encode_png(rgb, *, dpi: float, level: int = PNG_COMPRESSION) -> bytes:
    """PNG bytes of an ``(h, w, 3)`` uint8 image, every row unfiltered.

    Pillow tries all five PNG filters on every row and keeps the best, which costs more than
    the compression; a plot is mostly flat colour, which deflate packs well without a
    filter (the files come out smaller than Pillow's at the same level). The figures are
    opaque, so RGB: a quarter fewer bytes to compress than RGBA.
    """
    rgb = np.asarray(rgb, dtype=np.uint8)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected an (h, w, 3) image, not {rgb.shape}")
    height, width = rgb.shape[:2]
    rows = np.empty((height, 1 + 3 * width), dtype=np.uint8)
    rows[:, 0] = 0                                              # filter: none
    # straight from the canvas (the RGB of its RGBA), no intermediate, a channel at a time:
    # numpy copies a plane of single bytes three times faster than (h, w, 3) whole (its
    # innermost loop would be three bytes long)
    pixels = rows[:, 1:].reshape(height, width, 3, copy=False)
    for channel in range(3):
        pixels[:, :, channel] = rgb[:, :, channel]

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data)))

    per_metre = round(dpi / 0.0254)
    return b"".join([b"\x89PNG\r\n\x1a\n",
                     chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)),
                     chunk(b"pHYs", struct.pack(">IIB", per_metre, per_metre, 1)),
                     chunk(b"IDAT", zlib.compress(rows, level)),
                     chunk(b"IEND", b"")])
