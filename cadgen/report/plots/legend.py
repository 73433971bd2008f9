"""A figure's legend under its axes, drawn as plain artists: a sample and a label per entry.

matplotlib's ``Legend`` lays its entries out as a tree of offset boxes that it measures again
at every draw, which cost about a sixth of a report figure. The report's legends are all one
kind: entries in columns, filled column by column, at the foot of the figure, without a frame.
Here they are placed once, in inches from the figure's foot, with matplotlib's spacings and
sample shapes (a line with its marker in the middle, a patch or a filled collection as a
rectangle with its colours and hatch), and centred when the layout has fixed the figure's
width (:func:`cadgen.report.plots.layout.fit_layout`).
"""

from __future__ import annotations

import weakref

import numpy as np

__all__ = ["FootLegend", "foot_legend", "foot_legend_of"]

#: matplotlib's legend spacings (rcParams ``legend.*``), in font sizes.
_HANDLE_LENGTH, _HANDLE_HEIGHT, _HANDLE_PAD = 2.0, 0.7, 0.8
_COLUMN_SPACING, _LABEL_SPACING, _BORDER_PAD, _BORDER_AXES_PAD = 2.0, 0.5, 0.4, 0.5

#: The legend of each figure that has one (the layout asks for it).
_LEGENDS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


class FootLegend:
    """Entries laid out in inches; :meth:`place` centres them on a figure ``width`` wide.

    Attributes
    ----------
    width, height : float
        The legend's box (in), border padding included.
    below : float
        Inches from the figure's foot to the top of the legend's box: the room the axes
        leave under them.
    artists : list
        The samples and labels, added to the figure.
    """

    def __init__(self, figure, handles, labels, *, ncols: int, fontsize: float, dpi: float):
        from matplotlib.text import Text
        from matplotlib.transforms import Affine2D

        from cadgen.report.plots.layout import text_metrics

        self._shift = Affine2D()
        where = self._shift + figure.dpi_scale_trans       # inches, shifted by place()
        em = fontsize / 72
        _, height, descent = text_metrics("lp", fontsize, dpi)
        ascent = height - descent
        row = max(height, _HANDLE_HEIGHT * em)
        # matplotlib fills columns first, the first ones a row longer when the split is uneven
        count, ncols = len(labels), max(1, ncols)
        shortest, longer = divmod(count, ncols)
        sizes = [n for n in [shortest + 1] * longer + [shortest] * (ncols - longer) if n]
        starts = np.cumsum([0] + sizes)
        columns = [list(range(a, b)) for a, b in zip(starts[:-1], starts[1:])]
        rows = max(sizes, default=0)
        widths = [max(text_metrics(labels[k], fontsize, dpi)[0] for k in column)
                  for column in columns]
        pad = _BORDER_PAD * em
        self.height = 2 * pad + rows * row + (rows - 1) * _LABEL_SPACING * em
        self.width = 2 * pad + sum((_HANDLE_LENGTH + _HANDLE_PAD) * em + w for w in widths) \
            + (len(columns) - 1) * _COLUMN_SPACING * em
        self.below = _BORDER_AXES_PAD * em + self.height
        self.artists = []
        x = pad
        for column, width in zip(columns, widths):
            for index, k in enumerate(column):
                top = self.below - pad - index * (row + _LABEL_SPACING * em)
                baseline = top - (row - height) / 2 - ascent
                self.artists += _sample(handles[k], x, baseline, _HANDLE_LENGTH * em,
                                        _HANDLE_HEIGHT * em, where)
                self.artists.append(Text(x + (_HANDLE_LENGTH + _HANDLE_PAD) * em, baseline,
                                         labels[k], fontsize=fontsize, va="baseline",
                                         ha="left", transform=where))
            x += (_HANDLE_LENGTH + _HANDLE_PAD) * em + width + _COLUMN_SPACING * em
        for artist in self.artists:
            figure.add_artist(artist)

    def place(self, figure_width: float) -> None:
        """Centre the legend on a figure ``figure_width`` inches wide."""
        self._shift.clear().translate((figure_width - self.width) / 2, 0.0)


def foot_legend(figure, handles, labels, *, ncols: int, fontsize: float, dpi: float):
    """Put a :class:`FootLegend` on ``figure`` (replacing one it had).

    Entries whose artist has no sample (a text, say) are left out, as matplotlib's legend
    leaves them out.
    """
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    kept = [(h, label) for h, label in zip(handles, labels)
            if isinstance(h, (Line2D, Patch, Collection))]
    handles, labels = [h for h, _ in kept], [label for _, label in kept]
    old = _LEGENDS.get(figure)
    if old is not None:
        for artist in old.artists:
            artist.remove()
    legend = FootLegend(figure, handles, labels, ncols=ncols, fontsize=fontsize, dpi=dpi)
    _LEGENDS[figure] = legend
    return legend


def foot_legend_of(figure):
    """The figure's :class:`FootLegend`, or None."""
    return _LEGENDS.get(figure)


def _sample(handle, x, baseline, length, height, transform) -> list:
    """The artists showing ``handle`` in a ``length`` by ``height`` box (in) at ``x``, its
    foot on ``baseline``: matplotlib's samples, a line with its marker in the middle or a
    rectangle with the patch's or collection's colours."""
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    if isinstance(handle, Line2D):
        middle = baseline + height / 2
        line = Line2D([x, x + length / 2, x + length], [middle] * 3)
        line.update_from(handle)       # (its transform and clipping too: reset below)
        line.set_markevery([1])        # one marker, in the middle
        return [_unclipped(line, transform)]
    box = Rectangle((x, baseline), length, height, transform=transform)
    if isinstance(handle, Patch):
        box.update_from(handle)
        return [_unclipped(box, transform)]
    if isinstance(handle, Collection):
        def first(values, default):
            return values[0] if len(values) else default

        box.set_facecolor(tuple(first(np.asarray(handle.get_facecolor()), (0, 0, 0, 0))))
        box.set_edgecolor(tuple(first(np.asarray(handle.get_edgecolor()), (0, 0, 0, 0))))
        box.set_linewidth(first(handle.get_linewidths(), 0.0))
        box.set_hatch(handle.get_hatch())
        if handle.get_hatch():
            box.set_hatchcolor(tuple(first(np.asarray(handle.get_hatchcolor()), (0, 0, 0, 1))))
            box.set_hatch_linewidth(handle.get_hatch_linewidth())
        return [box]
    raise TypeError(f"no legend sample for a {type(handle).__name__}")


def _unclipped(artist, transform):
    artist.set_transform(transform)
    artist.set_clip_box(None)
    artist.set_clip_path(None)
    return artist
