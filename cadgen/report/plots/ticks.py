"""Each axis' ticks drawn as a few batched artists instead of one :class:`~matplotlib.axis.Tick`
per location.

matplotlib makes a Tick object per tick location at the draw (three lines and two texts,
each new one a copy of the first: its markers deep-copied), then draws its grid line and its
mark one by one: about two fifths of a report figure's drawing went there. Once the layout has
fixed the axes (:func:`cadgen.report.plots.layout.fit_layout`), the ticks an axis will draw
are known: the same locations, labels and in-view test as ``Axis._update_ticks``. They are
drawn here from the axis' first tick (the template every other tick copies): one line for all
the grid lines, one marker line per side for the tick marks, a text per label, with the
template's styles, transforms and clipping, in the order a tick draws its parts; the axis
itself is left to draw its label only (a :class:`~matplotlib.ticker.NullLocator`). Same
pixels.

An axis keeps matplotlib's ticks when its ticks are anything else than the plain case: minor
ticks, an offset or scale text ("1e6"), a hidden axis, or ticks whose parts differ.
"""

from __future__ import annotations

import numpy as np

__all__ = ["batch_ticks"]


def batch_ticks(figure) -> None:
    """Replace the ticks of every axis of ``figure`` (child axes included) by batched artists.

    Call after the layout, just before the draw: the view limits must be final.
    """
    from matplotlib.ticker import NullLocator

    plans = []
    for ax in _all_axes(figure):
        for axis in (ax.xaxis, ax.yaxis):
            artists = _plan(axis)
            if artists is not None:
                plans.append((ax, axis, artists))
    # (shared axes share one locator: every plan is made before any locator is replaced)
    for ax, axis, artists in plans:
        axis.set_major_locator(NullLocator())
        container = _Batched(artists)
        container.set_zorder(axis.get_zorder())
        ax.add_artist(container)
        container.set_clip_path(None)


def _all_axes(figure):
    stack = list(figure.axes)
    seen = []
    while stack:
        ax = stack.pop(0)
        if ax not in seen:
            seen.append(ax)
            stack.extend(ax.child_axes)
    return seen


def _plan(axis):
    """The artists that draw ``axis``' ticks as matplotlib would, or None to leave it be."""
    from matplotlib.ticker import NullLocator

    if not axis.get_visible() or isinstance(axis.get_major_locator(), NullLocator):
        return None
    if not isinstance(axis.get_minor_locator(), NullLocator):
        return None
    locations = np.asarray(axis.get_majorticklocs(), dtype=float)
    labels = axis.get_major_formatter().format_ticks(locations)
    if axis.get_major_formatter().get_offset():
        return None
    template = axis.get_major_ticks(1)[0]
    if not template.get_visible():
        return [] if len(locations) else None
    keep = _in_view(axis, locations)
    locations = locations[keep]
    labels = [label for label, k in zip(labels, keep) if k]
    if not len(locations):
        return []
    figure = axis.get_figure(root=False)
    along = 0 if axis.axis_name == "x" else 1
    artists = []
    for part in (template.gridline, template.tick1line, template.tick2line):
        if part.get_visible():
            artists.append(_lines_like(part, locations, along, figure,
                                       separate=part is template.gridline))
    for part in (template.label1, template.label2):
        if part.get_visible():
            artists += [_text_like(part, location, label, along, figure)
                        for location, label in zip(locations, labels)]
    return artists


def _in_view(axis, locations) -> np.ndarray:
    """``Axis._update_ticks``' test: inside the view interval (in the scale's coordinates),
    with a relative slack of 1e-10."""
    low, high = sorted(axis.get_view_interval())
    transform = axis.get_transform()
    a, b = sorted(float(v) for v in transform.transform([low, high]))
    slack = (b - a) * 1e-10
    placed = np.asarray(transform.transform(locations), dtype=float).reshape(-1)
    return (placed >= a - slack) & (placed <= b + slack)


def _lines_like(part, locations, along, figure, *, separate):
    """One line with ``part``'s style through ``part``'s data moved to each location: a
    marker at each (the tick marks, drawn as one marker line) or, ``separate``, a segment at
    each (the grid lines, NaN-separated)."""
    from matplotlib.lines import Line2D

    data = [np.asarray(part.get_xdata(), dtype=float), np.asarray(part.get_ydata(), dtype=float)]
    count = len(data[0])
    if separate:
        fixed = np.tile(np.append(data[1 - along], np.nan), len(locations))
        moving = np.repeat(locations, count + 1)
        moving[count::count + 1] = np.nan
    else:
        fixed = np.tile(data[1 - along], len(locations))
        moving = np.repeat(locations, count)
    xy = (moving, fixed) if along == 0 else (fixed, moving)
    line = Line2D(*xy)
    line.update_from(part)
    line.set_antialiased(part.get_antialiased())
    line.set_snap(part.get_snap())
    line.set_figure(figure)
    return line


def _text_like(part, location, label, along, figure):
    """A text with ``part``'s style at ``part``'s position moved to ``location``."""
    from matplotlib.text import Text

    x, y = part.get_position()
    text = Text(*((location, y) if along == 0 else (x, location)), label)
    text.update_from(part)
    text.set_rotation_mode(part.get_rotation_mode())
    text.set_figure(figure)
    return text


def _batched_class():
    from matplotlib.artist import Artist

    class Batched(Artist):
        """Draws its artists in their order (an axis' ticks, after the layout)."""

        def __init__(self, artists):
            super().__init__()
            self._artists = list(artists)

        def draw(self, renderer):
            if not self.get_visible():
                return
            for artist in self._artists:
                artist.draw(renderer)
            self.stale = False

        def get_window_extent(self, renderer=None):
            from matplotlib.transforms import Bbox

            return Bbox.null()

    return Batched


def _Batched(artists):
    global _BATCHED
    if _BATCHED is None:
        _BATCHED = _batched_class()
    return _BATCHED(artists)


_BATCHED = None
