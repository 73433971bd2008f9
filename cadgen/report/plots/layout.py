"""Placing a figure's axes without a layout engine: margins from the few texts round them.

matplotlib's constrained layout finds a figure's margins in a pre-draw that asks every
artist for its tight box (every tick of every axis laid out), which cost the report more than
drawing its figures. The report's figures are grids whose decorations are known: tick
labels, axis labels, titles, a top axis of event names, a title above the grid and a legend
below it. Here their sizes are measured from their strings (text metrics cached across
figures), the axes are placed in inches, and the axis labels and titles are pinned where the
margins were measured for, so that the draw does not search for them either.

A grid of equal-aspect drawings gets a figure of its own proportions: the given height is a
ceiling, not a size, so a flat drawing leaves no empty bands above and below it and a tall one
none beside it (the figure narrows, down to what its legend and titles need).
"""

from __future__ import annotations

import functools

import numpy as np

from cadgen.report.plots.legend import foot_legend_of

__all__ = ["fit_layout", "text_metrics"]

#: Inches per typographic point.
_POINT = 1 / 72
#: Room (in) between the outermost decoration and the figure's edge, and between two cells
#: beyond what their labels need.
_EDGE, _CELL_GAP = 0.08, 0.15
#: Least room (in) right of an axes: the half of a last tick label centred on its corner.
_MIN_RIGHT = 0.12
_SIDES = ("left", "right", "bottom", "top")


def fit_layout(figure, *, dpi: float) -> None:
    """Size ``figure`` and place its axes so that every decoration fits.

    The axes come from one grid (``Figure.subplots``), twins (``twinx``) and child axes
    (``secondary_xaxis``) included. Figure texts anchored at their top (a title over the
    grid) go above it, the figure's :class:`~cadgen.report.plots.legend.FootLegend` below
    it. ``dpi`` is the figure's resolution (text metrics are in pixels).
    """
    cells = _cells(figure)
    if not cells:
        return
    grid = next(iter(cells.values()))[0].get_subplotspec().get_gridspec()
    nrows, ncols = grid.get_geometry()
    width_ratios = np.asarray(grid.get_width_ratios() or [1.0] * ncols, dtype=float)
    height_ratios = np.asarray(grid.get_height_ratios() or [1.0] * nrows, dtype=float)
    given_width, ceiling = (float(v) for v in figure.get_size_inches())
    equal = all(_aspect_box(axes[0]) for axes in cells.values())
    renderer = _renderer(dpi)
    over = [t for t in figure.texts if t.get_verticalalignment() == "top" and t.get_text()]
    legend = foot_legend_of(figure)
    above = sum(_extent(text, renderer)[1] + _EDGE for text in over)
    below = legend.below if legend is not None else 0.0
    # what a narrowed figure must still hold across: its legend and titles, and in each
    # column the titles and axis labels over and under it
    wide = [_extent(text, renderer)[0] + 2 * _EDGE for text in over]
    if legend is not None:
        wide.append(legend.width + 2 * _EDGE)
    narrowest = np.zeros(ncols)
    for (_, (c0, c1)), axes in cells.items():
        texts = [t for ax in axes for t in (ax.title, ax.xaxis.label) if t.get_text()]
        if texts and c1 - c0 == 1:
            narrowest[c0] = max(narrowest[c0], max(_extent(t, renderer)[0] for t in texts))
    least = max(wide + [1.0])
    rooms = {key: dict.fromkeys(_SIDES, 0.0) for key in cells}
    for _ in range(6):      # the rooms depend on the ticks, the ticks on the axes' lengths
        left = _EDGE + max(rooms[key]["left"] for key in cells if key[1][0] == 0)
        right = _EDGE + max(rooms[key]["right"] for key in cells if key[1][1] == ncols)
        top = _EDGE + above + max(rooms[key]["top"] for key in cells if key[0][0] == 0)
        bottom = _EDGE + below + max(rooms[key]["bottom"] for key in cells
                                     if key[0][1] == nrows)
        column_gaps = np.array([_gap(rooms, 1, j, "right", "left") for j in range(ncols - 1)])
        row_gaps = np.array([_gap(rooms, 0, i, "bottom", "top") for i in range(nrows - 1)])
        span = given_width - left - right - column_gaps.sum()
        widths = span * width_ratios / width_ratios.sum()
        width, shift = given_width, 0.0
        if equal:
            widths, heights = _equal_rows(cells, widths, column_gaps, nrows, narrowest,
                                          ceiling - top - bottom - row_gaps.sum(), ceiling)
            used = widths.sum() + left + right + column_gaps.sum()
            if used < given_width - 1e-9:       # narrowed: down to its legend and titles
                width = max(used, least)
                shift = (width - used) / 2
            height = heights.sum() + top + bottom + row_gaps.sum()
        else:
            height = ceiling
            heights = ((height - top - bottom - row_gaps.sum()) * height_ratios
                       / height_ratios.sum())
        figure.set_size_inches(width, height)
        boxes = _boxes(cells, left + shift, bottom, widths, heights, column_gaps, row_gaps)
        for key, axes in cells.items():
            x, y, w, h = boxes[key]
            for ax in axes:
                ax.set_position([x / width, y / height, w / width, h / height])
        measured = {key: _measure(axes, boxes[key], renderer) for key, axes in cells.items()}
        if all(measured[key][0][side] <= rooms[key][side] + 1e-9
               for key in cells for side in _SIDES):
            break
        rooms = {key: {side: max(rooms[key][side], measured[key][0][side]) for side in _SIDES}
                 for key in cells}
    for _, pins in measured.values():
        for pin in pins:
            pin()
    for text in over:
        text.set_position((0.5, 1 - _EDGE / height))
    if legend is not None:
        legend.place(width)


# ------------------------------------------------------------------------------------------
# The grid


def _cells(figure) -> dict:
    """``{((row0, row1), (col0, col1)): [axes, its twins...]}`` in the figure's order."""
    cells: dict = {}
    for ax in figure.axes:
        spec = ax.get_subplotspec()
        if spec is not None:
            key = ((spec.rowspan.start, spec.rowspan.stop),
                   (spec.colspan.start, spec.colspan.stop))
            cells.setdefault(key, []).append(ax)
    return cells


def _gap(rooms, dimension, index, before, after) -> float:
    """Inches between row/column ``index`` and the next: both cells' labels and a gap."""
    ending = [room[before] for key, room in rooms.items() if key[dimension][1] == index + 1]
    starting = [room[after] for key, room in rooms.items() if key[dimension][0] == index + 1]
    return _CELL_GAP + max(ending + [0.0]) + max(starting + [0.0])


def _equal_rows(cells, widths, column_gaps, nrows, narrowest, free, ceiling) -> tuple:
    """``(widths, heights)`` of a grid of equal-aspect drawings: each row as high as its
    tallest drawing at the columns' widths; rows higher than the ``free`` height under the
    ceiling make every column narrower, down to what its titles need (a drawing narrower
    than its column is centred in it)."""
    heights = np.zeros(nrows)
    for (rows, columns), axes in cells.items():
        across = widths[columns[0]:columns[1]].sum() + column_gaps[columns[0]:columns[1] - 1].sum()
        heights[rows[0]] = max(heights[rows[0]], across * _box_ratio(axes[0]))
    free = max(free, 0.2 * ceiling)     # (decorations taller than the ceiling: a fifth kept)
    if heights.sum() > free:
        shrink = free / heights.sum()
        widths = np.maximum(widths * shrink, np.minimum(narrowest, widths))
        heights = heights * shrink
    return widths, heights


def _boxes(cells, left, bottom, widths, heights, column_gaps, row_gaps) -> dict:
    """``{cell: (x0, y0, width, height)}`` in inches from the figure's bottom-left corner
    (rows count from the top)."""
    xs = left + np.concatenate([[0.0], np.cumsum(widths[:-1] + column_gaps)])
    # the bottom of each row: what lies below it, from the bottom row up
    below = np.concatenate([[0.0], np.cumsum(heights[::-1][:-1] + row_gaps[::-1])])[::-1]
    boxes = {}
    for key in cells:
        (r0, r1), (c0, c1) = key
        w = widths[c0:c1].sum() + column_gaps[c0:c1 - 1].sum()
        h = heights[r0:r1].sum() + row_gaps[r0:r1 - 1].sum()
        boxes[key] = (float(xs[c0]), float(bottom + below[r1 - 1]), float(w), float(h))
    return boxes


def _aspect_box(ax) -> bool:
    return ax.get_aspect() != "auto" and ax.get_adjustable() == "box"


def _box_ratio(ax) -> float:
    """Height over width of the box an equal-aspect drawing fills."""
    return float(ax.get_aspect()) * ax.get_data_ratio()

# ------------------------------------------------------------------------------------------
# Measuring


@functools.lru_cache(maxsize=2)
def _renderer(dpi: float):
    """A 1-pixel Agg renderer: text metrics need the resolution, not a canvas."""
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(1, 1, dpi)


@functools.lru_cache(maxsize=4096)
def text_metrics(text: str, points: float, dpi: float) -> tuple:
    """``(width, height, descent)`` in inches of a line of text in the default font, as
    matplotlib lays it out (at least as high and as deep as "lp")."""
    from matplotlib.font_manager import FontProperties

    renderer, prop = _renderer(dpi), FontProperties(size=points)
    ismath = "TeX" if text.count("$") >= 2 else False
    w, h, d = renderer.get_text_width_height_descent(text, prop, ismath=ismath)
    _, lp_h, lp_d = renderer.get_text_width_height_descent("lp", prop, ismath=False)
    descent = max(d, lp_d)
    return w / dpi, (max(h - d, lp_h - lp_d) + descent) / dpi, descent / dpi


def _extent(artist, renderer) -> tuple:
    """``(width, height)`` in inches of an artist's box (a text or a legend)."""
    box = artist.get_window_extent(renderer)
    return box.width / renderer.dpi, box.height / renderer.dpi


def _measure(axes, box, renderer) -> tuple:
    """``(room, pins)``: the inches a cell's decorations take on each side of its ``box``
    (``(x0, y0, w, h)``, in), and the calls that pin its axis labels and titles there.

    An equal-aspect drawing narrower or lower than its box is centred in it; what its
    decorations need is counted from the drawing, less the box's part left free beside it.
    """
    import matplotlib as mpl

    room = dict.fromkeys(_SIDES, 0.0)
    pins = []
    size = axes[0].get_figure(root=True).get_size_inches()
    for ax in axes:
        ax.apply_aspect()
        x0, y0, x1, y1 = ax.get_position().extents * np.tile(size, 2)
        inches = (x1 - x0, y1 - y0)
        free = {"left": x0 - box[0], "right": box[0] + box[2] - x1,
                "bottom": y0 - box[1], "top": box[1] + box[3] - y1}
        needs = dict.fromkeys(_SIDES, 0.0)
        overhang = dict.fromkeys(_SIDES, 0.0)
        under_title = 0.0
        for child in ax.child_axes:
            child.apply_aspect()
        for owner in [ax, *ax.child_axes]:
            for axis, length in ((owner.xaxis, inches[0]), (owner.yaxis, inches[1])):
                if not axis.get_visible():
                    continue
                for side, depth, label_at in _axis_depths(axis, renderer, length, overhang):
                    if side == "top":       # the title goes above whatever is there
                        under_title = max(under_title, depth)
                    needs[side] = max(needs[side], depth)
                    if label_at is not None:
                        across = inches[1] if axis.axis_name == "x" else inches[0]
                        pins.append(_label_pin(axis, side, label_at / across))
        if ax.get_title():
            pad = under_title + mpl.rcParams["axes.titlepad"] * _POINT
            needs["top"] = max(needs["top"], pad + _extent(ax.title, renderer)[1])
            pins.append(_title_pin(ax, pad))
        needs["right"] = max(needs["right"], _MIN_RIGHT)
        for side in _SIDES:
            room[side] = max(room[side], max(needs[side], overhang[side]) - free[side])
    return room, pins


def _axis_depths(axis, renderer, length, overhang):
    """``(side, inches, label distance or None)`` for each side an axis draws on: how far its
    tick labels and label reach out of the axes, and where the label goes. Tick labels that
    stick out past the axis' ends raise ``overhang``."""
    params = axis.get_tick_params()
    first, second = ("bottom", "top") if axis.axis_name == "x" else ("left", "right")
    ticks = _tick_boxes(axis, renderer.dpi, length, overhang) \
        if params.get(f"label{first}") or params.get(f"label{second}") else None
    label = axis.label.get_text() and axis.label.get_visible()
    out = []
    # a scale or offset the formatter took out of the labels ("1e6", "+1e7"): over a y axis'
    # end, under an x axis' labels (the axis label under it)
    offset = _offset_height(axis, renderer.dpi) if ticks is not None else 0.0
    if offset and axis.axis_name == "y":
        out.append(("top", offset, None))
    for side in (first, second):
        depth = 0.0
        if ticks is not None and params.get(f"label{side}"):
            depth = ticks + (offset if axis.axis_name == "x" else 0.0)
        label_at = None
        if label and axis.get_label_position() == side:
            label_at = depth + axis.labelpad * _POINT
            depth = label_at + _extent(axis.label, renderer)[1 if axis.axis_name == "x" else 0]
        if depth:
            out.append((side, depth, label_at))
    return out


def _tick_boxes(axis, dpi, length, overhang) -> float:
    """How far (in) an axis' tick labels reach out of the axes; their overhang past its ends
    goes into ``overhang``."""
    import matplotlib as mpl
    from matplotlib.font_manager import FontProperties

    name = axis.axis_name
    params = axis.get_tick_params()
    points = FontProperties(size=params.get("labelsize", mpl.rcParams[f"{name}tick.labelsize"])
                            ).get_size_in_points()
    size = params.get("length", mpl.rcParams[f"{name}tick.major.size"])
    pad = params.get("pad", mpl.rcParams[f"{name}tick.major.pad"])
    direction = params.get("direction", mpl.rcParams[f"{name}tick.direction"])
    outward = size * {"out": 1.0, "inout": 0.5, "in": 0.0}[direction]
    labels, fractions = _tick_labels(axis)
    if not labels:
        return 0.0
    # the draw makes these ticks anyway; a rotation set on their labels counts
    tick = axis.get_major_ticks(1)[0]
    rotation = np.radians(tick.label1.get_rotation() or tick.label2.get_rotation())
    aligned_left = tick.label2.get_horizontalalignment() == "left" and rotation
    sizes = np.array([text_metrics(label, points, dpi)[:2] for label in labels])
    cos, sin = abs(np.cos(rotation)), abs(np.sin(rotation))
    horizontal = sizes[:, 0] * cos + sizes[:, 1] * sin
    vertical = sizes[:, 0] * sin + sizes[:, 1] * cos
    across, along = (vertical, horizontal) if name == "x" else (horizontal, vertical)
    centres = fractions * length
    low, high = (centres, centres + along) if aligned_left else (centres - along / 2,
                                                                 centres + along / 2)
    start, end = ("left", "right") if name == "x" else ("bottom", "top")
    overhang[start] = max(overhang[start], float(-low.min()))
    overhang[end] = max(overhang[end], float(high.max() - length))
    return (outward + pad) * _POINT + float(across.max())


def _offset_height(axis, dpi) -> float:
    """Inches the axis' offset text ("1e6") takes, with matplotlib's gap, or 0 when none."""
    from matplotlib.font_manager import FontProperties

    offset = axis.get_major_formatter().get_offset() if axis.offsetText.get_visible() else ""
    if not offset:
        return 0.0
    points = FontProperties(size=axis.offsetText.get_fontsize()).get_size_in_points()
    return text_metrics(offset, points, dpi)[1] + axis.OFFSETTEXTPAD * _POINT


def _tick_labels(axis) -> tuple:
    """The tick labels the draw will show: ``(strings, fractions along the axis)``."""
    locations = np.asarray(axis.get_majorticklocs(), dtype=float)
    if not len(locations):
        return [], np.zeros(0)
    # formatted all at once, as the draw does (a fixed formatter counts positions)
    labels = axis.get_major_formatter().format_ticks(locations)
    low, high = axis.get_view_interval()
    span = (high - low) or 1.0
    fractions = (locations - low) / span
    keep = (fractions >= -1e-10) & (fractions <= 1 + 1e-10) & np.array([bool(s) for s in labels])
    return [label for label, k in zip(labels, keep) if k], fractions[keep]


def _label_pin(axis, side, distance):
    """Pin an axis label at ``distance`` (a fraction of the axes' size) out of ``side``."""
    where = {"bottom": (0.5, -distance), "top": (0.5, 1 + distance),
             "left": (-distance, 0.5), "right": (1 + distance, 0.5)}[side]
    return lambda: axis.set_label_coords(*where)


def _title_pin(ax, pad):
    """Pin a title ``pad`` inches above its axes (what a top axis needs included)."""
    title, size = ax.get_title(), ax.title.get_fontsize()
    return lambda: ax.set_title(title, y=1.0, pad=pad / _POINT, fontsize=size)
