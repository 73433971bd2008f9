"""Drawings of the split gearbox housings: a plan view and a section through the bearing seats.

One figure per :class:`~cadgen.solids.split_housing.SplitHousing`, for a machine
designer who would rather read a drawing than the report's tables:

* the *plan* (seen from above, in the housing's frame): flange, outer wall, the
  cavity as a hidden (dashed) line, the bolt holes, each bearing seat and its
  through hole, labelled with the shaft and the bearing (``"D 6002"``), and the
  line the section is cut along;
* the *section* along the line of the seats (their principal axis; ``x`` for a
  single seat), z up: base and cover in two fills, the parting plane, the flange
  halves, each seat as deep as its bearing is wide, the shoulder holes, the shafts
  when the drivetrain is given, and dimensions of the end walls and the cavity.

Both views are at one scale (mm, equal axes). A long housing (gearbox 1 of the
planting mechanism is about 580 by 120 mm) is drawn with its plan above its
section, its long side across the page, the plan turned a quarter turn when that
side is ``y`` so the section lies right under the seats it cuts; a squarer one has
its views side by side. The sizes are derived from the housing, so the bytes are a
fixed function of it (see :func:`cadgen.report.plots.base._png`).

matplotlib and shapely are imported inside the functions.
"""

from __future__ import annotations

import re

import numpy as np

from cadgen.report.plots.base import (_add_patch, _figure, _fill, _legend_below, _png,
                                      _suptitle)

__all__ = ["housing_figure", "housing_figure_jobs", "STACK_ASPECT"]

#: A plan whose long side is at least this many times its short side is drawn above its
#: section, both the long way across the page; a squarer one beside it.
STACK_ASPECT = 1.5

_BASE, _COVER = "#8fa3b8", "#d9b77e"          # the two halves (the base as in the assembly view)
_FLANGE, _OUTER = "#e8edf2", "#c5d1dc"        # plan: flange ring, the roof inside the outer wall
_SEAT, _SEAT_FILL = "tab:red", "#f6d5d1"
_HOLE, _SHAFT = "0.25", "#ececec"
_FONT = 7
#: Figure width (in) and what the axes leave round a view: tick labels and axis label on the
#: left, the parting-plane label left of the section, the dimensions right of it.
_WIDTH = 9.0
_AXIS_IN, _PARTING_IN, _DIMENSIONS_IN = 0.75, 0.9, 1.0
#: Room (in) round the plan, for seat labels near its edge.
_PLAN_PAD_IN = 0.15
#: The tallest a housing's figure gets (in); below it, the height follows from the views.
_CEILING = 12.0


def housing_figure_jobs(housings: dict, drivetrain=None) -> dict:
    """``{"housing-<name>.png": callable -> PNG bytes}`` for every split housing of ``housings``.

    Entries that are not split housings (a closed shell has no seats or bolts) are skipped.
    ``drivetrain`` (:class:`cadgen.machine.model.Drivetrain`, optional) adds the shafts to the
    sections.
    """
    shafts = tuple(getattr(drivetrain, "shafts", None) or ()) or None
    jobs = {}
    for name, housing in housings.items():
        if not (hasattr(housing, "seats") and hasattr(housing, "bolt_positions")):
            continue
        slug = re.sub(r"[^a-z0-9]+", "-", str(name).lower()).strip("-")
        jobs[f"housing-{slug}.png"] = (lambda name=name, housing=housing:
                                       housing_figure(name, housing, shafts=shafts))
    return jobs


def housing_figure(name: str, housing, *, shafts=None) -> bytes:
    """Plan and section of a split housing, as PNG bytes.

    Parameters
    ----------
    name : str
        The housing's name, for the title (``"gearbox1"``).
    housing : SplitHousing
        See :mod:`cadgen.solids.split_housing`.
    shafts : sequence of cadgen.machine.model.Shaft, optional
        Drawn in the section where one of this housing's seats holds them (matched by
        shaft name and side).
    """
    centre, direction = _section_line(housing)
    section = _section(housing, centre, direction)
    flange = np.asarray(housing.flange_outline, dtype=float)
    spans = np.ptp(flange, axis=0)
    stacked = bool(spans.max() >= STACK_ASPECT * spans.min())
    turned = bool(stacked and spans[1] > spans[0])
    across = spans[1] if turned else spans[0]          # the plan's width on the page (mm)
    s_low, s_high = section["extent"]
    margins = _PARTING_IN + _DIMENSIONS_IN
    # a first scale (in per mm) from the housing alone, for the labels' room in mm; the
    # figure's final size comes from what was drawn
    if stacked:
        scale = (_WIDTH - _AXIS_IN - 0.2 - margins) / max(across, s_high - s_low)
        # a seat line within about 18 deg of the page's width: one x scale for both views
        aligned = abs(direction[1 if turned else 0]) > 0.95
        figure, (plan, cut) = _figure(_WIDTH, _CEILING, nrows=2, sharex=aligned)
        plan.tick_params(labelbottom=True)
    else:
        scale = (_WIDTH - 2 * _AXIS_IN - 0.3 - margins) / (across + s_high - s_low)
        figure, (plan, cut) = _figure(_WIDTH, _CEILING, ncols=2)
    _draw_plan(plan, housing, turned=turned, line=(centre, direction, section["extent"]),
               scale=scale)
    _draw_section(cut, housing, section, shafts=shafts, scale=scale, narrow=not stacked)
    pad = _PLAN_PAD_IN / scale
    box = np.asarray(plan.dataLim.extents)
    plan.update_datalim([box[:2] - pad, box[2:] + pad])
    cut.update_datalim([(s_low - _PARTING_IN / scale, housing.z_bottom),
                        (s_high + _DIMENSIONS_IN / scale, housing.z_top)])
    for ax in (plan, cut):
        ax.margins(0)
        ax.autoscale_view()
        ax.set_aspect("equal", adjustable="box")
        ax.tick_params(labelsize=_FONT)
    _one_scale(plan, cut, stacked)
    if turned:
        plan.invert_yaxis()   # up is -x: the plan turned, not mirrored (still seen from above)
    _suptitle(figure, f"{name}: base and cover, {len(housing.bolt_positions)} x "
                      f"{housing.bolt_size} bolts", fontsize=10)
    _legend_below(figure, ncols=4, fontsize=_FONT)
    return _png(figure)


def _one_scale(plan, cut, stacked) -> None:
    """Give both views one scale: the layout makes each equal-aspect view as wide as its
    column, so stacked views get x ranges of one length (the longer one's, each centred on
    its own drawing unless the axes are shared) and side-by-side columns are as wide as
    their drawings."""
    spans = [abs(np.subtract(*ax.get_xlim())) for ax in (plan, cut)]
    grid = plan.get_subplotspec().get_gridspec()
    if not stacked:
        grid.set_width_ratios(spans)
        return
    if plan.get_shared_x_axes().joined(plan, cut):
        return
    for ax in (plan, cut):
        middle = float(np.mean(ax.get_xlim()))
        ax.set_xlim(middle - max(spans) / 2, middle + max(spans) / 2)


def _circle(ax, centre, radius, **style):
    from matplotlib.patches import Circle

    return _add_patch(ax, Circle(centre, radius, **style), np.subtract(centre, radius),
                      np.add(centre, radius))


def _rectangle(ax, low, high, **style):
    from matplotlib.patches import Rectangle

    return _add_patch(ax, Rectangle(low, high[0] - low[0], high[1] - low[1], **style), low, high)


def _mm(value: float) -> str:
    """A length for a label: one decimal at most (``14``, ``11.1``)."""
    return f"{value:.1f}".rstrip("0").rstrip(".")

# ----------------------------------------------------------------------------------------------
# Geometry of the section


def _section_line(housing):
    """``(centre (2,), direction (2,))``: the line of the seats, its principal axis.

    The direction's larger component is positive, so the section reads the way the plan
    does; ``x`` when there is one seat position (or none; the centre is then the outline's).
    """
    points = np.asarray([seat.xy for seat in housing.seats], dtype=float).reshape(-1, 2)
    outline = np.asarray(housing.outer_outline, dtype=float)
    if len(points) == 0:
        return (outline.min(axis=0) + outline.max(axis=0)) / 2, np.array([1.0, 0.0])
    centre = points.mean(axis=0)
    spread = points - centre
    if np.abs(spread).max() <= 1e-9 * np.ptp(outline, axis=0).max():
        return centre, np.array([1.0, 0.0])
    direction = np.linalg.svd(spread, full_matrices=False)[2][0]
    if direction[np.argmax(np.abs(direction))] < 0:
        direction = -direction
    return centre, direction


def _section(housing, centre, direction) -> dict:
    """The housing cut along the line through ``centre`` along ``direction``, in ``(s, z)``.

    ``s = p . direction`` (mm), so a line along ``x`` or ``y`` keeps that coordinate. Returns
    ``base`` and ``cover`` (shapely geometries), ``seats`` (one ``(seat, s, (s0, s1), (z0,
    z1), hole)`` per seat the line cuts, ``hole`` the through hole's ``(s0, s1, z0, z1)`` or
    None), the spans of the outer wall and the cavity along the line, and the cut's ``extent``
    (the flange's ends).
    """
    import shapely

    normal = np.array([-direction[1], direction[0]])
    offset = float(centre @ normal)
    flange = np.asarray(housing.flange_outline, dtype=float)
    reach = 4.0 * float(np.abs(flange).max() + np.abs(centre).max())
    line = shapely.LineString([centre - reach * direction, centre + reach * direction])

    def spans(outline):
        cut = shapely.Polygon(outline).intersection(line)
        out = []
        for piece in getattr(cut, "geoms", [cut]):
            if isinstance(piece, shapely.LineString) and not piece.is_empty:
                s = np.asarray(piece.coords) @ direction
                out.append((float(s.min()), float(s.max())))
        return sorted(out)

    def chord(xy, diameter):
        # a circle off the line is cut narrower than its diameter, or not at all
        distance = abs(float(np.asarray(xy, dtype=float) @ normal) - offset)
        if distance >= diameter / 2:
            return None
        half = float(np.sqrt((diameter / 2) ** 2 - distance ** 2))
        s = float(np.asarray(xy, dtype=float) @ direction)
        return s - half, s + half

    z_bottom, z_top = housing.z_bottom, housing.z_top
    cavity_low = housing.z_cavity_bottom
    cavity_high = cavity_low + housing.cavity_height
    flange_low, flange_high = housing.flange_z
    outer_spans, flange_spans = spans(housing.outer_outline), spans(flange)
    cavity_spans = spans(housing.cavity_outline)
    solid = ([shapely.box(a, z_bottom, b, z_top) for a, b in outer_spans]
             + [shapely.box(a, flange_low, b, flange_high) for a, b in flange_spans])
    voids = [shapely.box(a, cavity_low, b, cavity_high) for a, b in cavity_spans]
    seats = []
    for seat in housing.seats:
        width = chord(seat.xy, float(seat.seat_diameter))
        if width is None:
            continue
        depth = float(getattr(seat, "depth", seat.bearing.width))   # a pair: two widths
        floor = seat.wall == "floor"
        z = (cavity_low - depth, cavity_low) if floor else (cavity_high, cavity_high + depth)
        voids.append(shapely.box(width[0], z[0], width[1], z[1]))
        hole = None
        if seat.through and (through := chord(seat.xy, float(seat.hole_diameter))):
            hole = (*through, *((z_bottom, z[0]) if floor else (z[1], z_top)))
            voids.append(shapely.box(hole[0], hole[2], hole[1], hole[3]))
        seats.append((seat, float(np.asarray(seat.xy, dtype=float) @ direction), width, z, hole))
    for xy in housing.bolt_positions:
        width = chord(xy, float(housing.bolt_hole_diameter))
        if width is not None:
            voids.append(shapely.box(width[0], flange_low, width[1], flange_high))
    for x, y, diameter, wall in getattr(housing, "passages", ()):   # a shaft passing a wall
        width = chord((x, y), float(diameter))
        if width is not None:
            voids.append(shapely.box(width[0], z_bottom if wall == "floor" else cavity_high,
                                     width[1], cavity_low if wall == "floor" else z_top))
    for x, y, diameter, depth, wall in getattr(housing, "tapped", ()):   # a flange's screws
        width = chord((x, y), float(diameter))
        if width is not None:
            voids.append(shapely.box(width[0], z_bottom if wall == "floor" else z_top - depth,
                                     width[1], z_bottom + depth if wall == "floor" else z_top))
    material = shapely.union_all(solid).difference(shapely.union_all(voids))
    far = reach + abs(z_bottom) + abs(z_top)
    base = material.intersection(shapely.box(-far, -far, far, housing.parting_z))
    cover = material.intersection(shapely.box(-far, housing.parting_z, far, far))
    ends = [s for span in flange_spans + outer_spans for s in span] or [0.0, 0.0]
    return {"base": base, "cover": cover, "seats": seats, "outer": outer_spans,
            "cavity": cavity_spans, "extent": (min(ends), max(ends))}


def _polygons(geometry):
    """The polygons of a shapely geometry (the lines and points a cut can leave dropped)."""
    import shapely

    if isinstance(geometry, shapely.Polygon):
        return [] if geometry.is_empty else [geometry]
    return [g for part in getattr(geometry, "geoms", []) for g in _polygons(part)]

# ----------------------------------------------------------------------------------------------
# The views


def _draw_plan(ax, housing, *, turned=False, line=None, scale=None) -> dict:
    """Draw the plan of ``housing`` on ``ax``; return what was drawn.

    Parameters
    ----------
    turned : bool
        Draw ``y`` across and ``x`` down (the caller inverts the vertical axis, so the
        plan is turned a quarter turn, not mirrored).
    line : (centre, direction, (s0, s1)), optional
        The section line to draw.
    scale : float, optional
        in per mm of the drawing, to keep seat labels from overlapping (default: labels
        alternate above and below the seats).

    Returns
    -------
    dict
        ``bolt_holes``, ``seats``, ``through_holes`` (matplotlib patches) and ``labels``
        (texts), one per bolt, per seat circle, per through hole, per seat position.
    """

    def view(points):
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        return (points[:, 1], points[:, 0]) if turned else (points[:, 0], points[:, 1])

    up = -1.0 if turned else 1.0      # the sign of "up the page" in the vertical data axis
    drawn = {"bolt_holes": [], "seats": [], "through_holes": [], "labels": [], "tapped": []}
    _fill(ax, *view(housing.flange_outline), facecolor=_FLANGE, edgecolor="k", linewidth=0.7,
          label="flange (plan)")
    _fill(ax, *view(housing.outer_outline), facecolor=_OUTER, edgecolor="k", linewidth=0.8,
          label="outer wall (plan)")
    cavity = np.asarray(housing.cavity_outline, dtype=float)
    ax.plot(*view(np.vstack([cavity, cavity[:1]])), color="k", ls="--", lw=0.7,
            label="cavity (hidden line)")
    radius = float(housing.bolt_hole_diameter) / 2
    bolt_label = (f"bolt hole {_mm(2 * radius)} mm ({len(housing.bolt_positions)} x "
                  f"{housing.bolt_size})")
    for index, xy in enumerate(np.asarray(housing.bolt_positions, dtype=float)):
        h, v = view(xy)
        drawn["bolt_holes"].append(_circle(
            ax, (h[0], v[0]), radius, facecolor="white", edgecolor="k", linewidth=0.6, zorder=3,
            label=bolt_label if index == 0 else None))
    groups: dict = {}     # one label per seat position: a floor and a roof seat share it
    for seat in housing.seats:
        groups.setdefault(tuple(np.round(np.asarray(seat.xy, dtype=float), 6)), []).append(seat)
    drawn_circles = set()
    for x, y, diameter, _ in getattr(housing, "passages", ()):
        h, v = (float(c[0]) for c in view((x, y)))
        drawn["through_holes"].append(_circle(
            ax, (h, v), float(diameter) / 2, facecolor=_HOLE, edgecolor="k", linewidth=0.6,
            zorder=4, label=None if drawn["through_holes"] else "through hole (shaft leaves)"))
    for x, y, diameter, depth, wall in getattr(housing, "tapped", ()):
        # tapped from the wall's outer face (a carrying flange's screws, the mounting holes)
        h, v = (float(c[0]) for c in view((x, y)))
        drawn["tapped"].append(_circle(
            ax, (h, v), float(diameter) / 2, facecolor="white", edgecolor="k", linewidth=0.6,
            linestyle="--", zorder=4,
            label=None if drawn["tapped"] else f"tapped hole in the {wall} (drill shown)"))
    for position, seats in groups.items():
        h, v = (float(c[0]) for c in view(position))
        for seat in seats:
            key = (position, round(float(seat.seat_diameter), 6))
            if key not in drawn_circles:
                drawn_circles.add(key)
                drawn["seats"].append(_circle(
                    ax, (h, v), float(seat.seat_diameter) / 2, facecolor=_SEAT_FILL,
                    edgecolor=_SEAT, linewidth=1.0, zorder=3,
                    label=None if drawn["seats"] else "bearing seat (seat bore)"))
            if seat.through:
                drawn["through_holes"].append(_circle(
                    ax, (h, v), float(seat.hole_diameter) / 2, facecolor=_HOLE, edgecolor="k",
                    linewidth=0.6, zorder=4,
                    label=None if drawn["through_holes"] else "through hole (shaft leaves)"))
        ax.plot([h], [v], "+", color="k", ms=4, mew=0.6, zorder=5)
    drawn["labels"] = _seat_labels(ax, groups, view, up, scale)
    if line is not None:
        centre, direction, (s0, s1) = line
        overshoot = 0.15 / scale if scale else 0.0
        ends = np.array([centre + (s - centre @ direction) * direction
                         for s in (s0 - overshoot, s1 + overshoot)])
        ax.plot(*view(ends), color="0.2", lw=0.7, ls=(0, (10, 3, 2, 3)), zorder=2,
                label="section line")
    ax.set_xlabel("y (mm)" if turned else "x (mm)", fontsize=_FONT + 1)
    ax.set_ylabel("x (mm)" if turned else "y (mm)", fontsize=_FONT + 1)
    ax.set_title("Plan, from above (housing frame)", fontsize=8)
    return drawn


def _seat_labels(ax, groups, view, up, scale):
    """``"D 6002"`` beside each seat position: above it, or below when the previous label
    above would overlap it (estimated widths at ``scale``), or alternating without a scale."""
    placed = []
    last_end = {1: -np.inf, -1: -np.inf}
    order = sorted(groups.items(), key=lambda item: float(view(item[0])[0][0]))
    for index, (position, seats) in enumerate(order):
        h, v = (float(c[0]) for c in view(position))
        names = list(dict.fromkeys(seat.shaft for seat in seats))
        bearings = list(dict.fromkeys(seat.bearing.designation for seat in seats))
        text = f"{'/'.join(names)} {'/'.join(bearings)}"
        radius = max(float(seat.seat_diameter) for seat in seats) / 2
        half = (0.55 * _FONT * len(text) / 72 / 2 + 0.03) / scale if scale else 0.0
        if scale:
            side = 1 if h - half > last_end[1] else (-1 if h - half > last_end[-1] else 1)
        else:
            side = 1 if index % 2 == 0 else -1
        last_end[side] = h + half
        placed.append(ax.annotate(
            text, (h, v + side * up * radius), xytext=(0, 3 * side), textcoords="offset points",
            ha="center", va="bottom" if side > 0 else "top", fontsize=_FONT, zorder=6,
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85}))
    return placed


def _draw_section(ax, housing, section, *, shafts=None, scale=1.0, narrow=False) -> None:
    """Draw the section (``_section``'s output) on ``ax``: halves, seats, shafts, parting
    plane, shaft names above and the end walls' and the cavity's dimensions on the right
    (``scale`` in per mm, for the labels' room; ``narrow``: the title on two lines)."""
    for geometry, colour, hatch, label in ((section["base"], _BASE, "///", "base (section)"),
                                           (section["cover"], _COVER, "\\\\\\",
                                            "cover (section)")):
        for index, polygon in enumerate(_polygons(geometry)):
            x, y = polygon.exterior.xy
            fill = _fill(ax, x, y, facecolor=colour, edgecolor="none", linewidth=0.0,
                         hatch=hatch, label=label if index == 0 else None)
            fill.set_hatchcolor("0.3")
            fill.set_hatch_linewidth(0.4)
            ax.plot(x, y, color="k", lw=0.7)
            for ring in polygon.interiors:
                _fill(ax, *ring.xy, facecolor="white", edgecolor="k", linewidth=0.7)
    z_bottom, z_top, parting = housing.z_bottom, housing.z_top, housing.parting_z
    by_shaft = {(shaft.name, shaft.side): shaft for shaft in shafts or ()}
    axes_of: dict = {}
    for seat, s, (s0, s1), (z0, z1), hole in section["seats"]:
        axes_of.setdefault(round(s, 6), []).append((seat, z0, z1, hole))
        _rectangle(ax, (s0, z0), (s1, z1), facecolor=_SEAT_FILL, edgecolor=_SEAT, linewidth=0.9,
                   zorder=4)
        if hole is not None:
            _rectangle(ax, (hole[0], hole[2]), (hole[1], hole[3]), facecolor="none",
                       edgecolor=_HOLE, linewidth=0.7, zorder=4)
    over = 0.08 / scale
    spans, shaft_label = {}, "shaft"
    for s, seats in axes_of.items():
        spans[s] = (z_bottom - over, z_top + over)
        shaft = by_shaft.get((seats[0][0].shaft, seats[0][0].side))
        if shaft is None:
            continue
        # the shaft between its seats' bottoms, out through a through hole (a stub)
        diameter = float(shaft.diameter)
        low = min([z_bottom - diameter / 2 if hole else z0
                   for seat, z0, _, hole in seats if seat.wall == "floor"]
                  or [housing.z_cavity_bottom])
        high = max([z_top + diameter / 2 if hole else z1
                    for seat, _, z1, hole in seats if seat.wall == "roof"]
                   or [housing.z_cavity_bottom + housing.cavity_height])
        _rectangle(ax, (s - diameter / 2, low), (s + diameter / 2, high), facecolor=_SHAFT,
                   edgecolor="0.35", linewidth=0.6, zorder=3.5, label=shaft_label)
        shaft_label = None     # one legend entry for all the shafts
        spans[s] = (min(low, z_bottom) - over, max(high, z_top) + over)
    # the shaft names in one row above the section and whatever sticks out of it
    row = max((high for _, high in spans.values()), default=z_top)
    for s, seats in axes_of.items():
        ax.plot([s, s], [spans[s][0], row], color="0.3", lw=0.5, ls=(0, (10, 3, 2, 3)),
                zorder=5)
        names = "/".join(dict.fromkeys(seat.shaft for seat, *_ in seats))
        ax.annotate(names, (s, row), xytext=(0, 1), textcoords="offset points",
                    ha="center", va="bottom", fontsize=_FONT)
    low = min((low for low, _ in spans.values()), default=z_bottom)
    ax.update_datalim([(section["extent"][0], low), (section["extent"][1],
                                                     row + (_FONT + 6) / 72 / scale)])
    s_low, s_high = section["extent"]
    ax.plot([s_low - 0.1 / scale, s_high + 0.1 / scale], [parting, parting], color="k",
            ls="--", lw=0.8, zorder=6)
    ax.annotate("parting plane", (s_low - 0.1 / scale, parting), xytext=(-3, 0),
                textcoords="offset points", ha="right", va="center", fontsize=_FONT)
    _end_dimensions(ax, housing, section, scale)
    ax.set_xlabel("along the seat line (mm)", fontsize=_FONT + 1)
    ax.set_ylabel("z (mm)", fontsize=_FONT + 1)
    low, high = housing.flange_z
    ax.set_title(f"Section along the seat line:{chr(10) if narrow else ' '}side wall "
                 f"{_mm(housing.wall)} mm, flange {_mm(parting - low)} + {_mm(high - parting)} "
                 f"mm, seats as deep as their bearings", fontsize=8)


def _end_dimensions(ax, housing, section, scale) -> None:
    """Dimension lines right of the section: floor, cavity and roof heights (mm)."""
    cavity_low = housing.z_cavity_bottom
    cavity_high = cavity_low + housing.cavity_height
    levels = [housing.z_bottom, cavity_low, cavity_high, housing.z_top]
    wall_end = max((b for _, b in section["outer"]), default=section["extent"][1])
    at = section["extent"][1] + 0.2 / scale
    for z in levels:        # extension lines from the outer wall's face
        ax.plot([wall_end, at + 0.05 / scale], [z, z], color="0.35", lw=0.4, zorder=6)
    for (z0, z1), what in zip(zip(levels[:-1], levels[1:]), ("floor", "cavity", "roof")):
        ax.annotate("", (at, z0), xytext=(at, z1), zorder=6,
                    arrowprops={"arrowstyle": "<|-|>,head_length=0.3,head_width=0.12",
                                "lw": 0.6, "color": "k", "shrinkA": 0, "shrinkB": 0})
        ax.annotate(f"{what} {_mm(z1 - z0)} mm", (at, (z0 + z1) / 2), xytext=(3, 0),
                    textcoords="offset points", ha="left", va="center", fontsize=_FONT)
