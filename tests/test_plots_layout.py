"""The report figures' layout, legend and PNG writer: every text round the axes inside the
figure and clear of the others (as matplotlib measures them after the draw), equal-aspect
drawings in figures of their own proportions, legend samples drawn, PNG bytes a decoder reads
back exactly."""

import io
import struct

import numpy as np
import pytest
from matplotlib.text import Text
from PIL import Image

from cadgen.report.plots.base import (DPI, _encode_png, _event_ticks, _figure, _fill,
                                      _legend_below, _png, _suptitle)
from cadgen.report.plots.legend import foot_legend_of

# ------------------------------------------------------------------------------------------
# Figures of each kind the report draws


def _curves():
    """One plot: long tick labels, a two-line title, a legend of lines, markers and a fill."""
    figure, ax = _figure(7.5, 5.0)
    x = np.linspace(0.0, 360.0, 721)
    ax.plot(x, 120000 * np.sin(np.radians(x)), label="speed of the tip at 30 r/min")
    ax.plot(x[::60], 90000 * np.cos(np.radians(x[::60])), "o", label="events")
    _fill(ax, [0, 90, 90, 0], [-1e5, -1e5, 1e5, 1e5], alpha=0.3, label="shaded range")
    ax.axhline(0.0, color="k", ls=":", label="zero line")
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle phi (deg)")
    ax.set_ylabel("tip speed (mm/s)")
    ax.set_title("A title over two lines,\nthe second as long as the first one is")
    _legend_below(figure, ncols=2)
    return figure


def _events():
    """Events named on a top axis, rotated, one at the right end; the title above them."""
    figure, ax = _figure(8.0, 5.0)
    ax.plot([0, 360], [-15, 10], label="attitude")
    _event_ticks(ax, {"entry": 160.0, "lowest": 190.0, "seedling cleared": 352.0},
                 rotation=30)
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle (deg)")
    ax.set_ylabel("attitude (deg)")
    ax.set_title("Events named above, the title above them")
    _legend_below(figure, ncols=1)
    return figure


def _twins():
    """Two plots sharing x, each with a twin y axis on the right (the cam's follower)."""
    figure, (top, bottom) = _figure(8.0, 6.5, nrows=2, sharex=True)
    x = np.linspace(0, 360, 100)
    for ax, scale in ((top, 2.5), (bottom, 14.0)):
        ax.plot(x, scale * np.sin(np.radians(x)) ** 2, label=f"left {scale}")
        ax.set_ylabel("left axis (mm)")
        twin = ax.twinx()
        twin.plot(x, 1000 * scale * np.cos(np.radians(x)), ls="--", label=f"right {scale}")
        twin.set_ylabel("right axis (deg)")
    _event_ticks(top, {"entry": 165.0, "seedling cleared": 236.0}, rotation=30)
    top.set_title("Two lines of title\nover the upper plot and its event names", fontsize=9)
    bottom.set_xlabel("carrier angle (deg)")
    _legend_below(figure, ncols=3, fontsize=7)
    return figure


def _drawing(width, height, title):
    """An equal-aspect drawing ``width`` by ``height`` mm."""
    figure, ax = _figure(7.0, 8.0)
    t = np.linspace(0, 2 * np.pi, 200)
    ax.plot(width / 2 * np.cos(t), height / 2 * np.sin(t), label="outline of the drawing")
    ax.plot([0], [0], "k+", label="centre of the drawing, marked")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(title, fontsize=9)
    _legend_below(figure, ncols=2)
    return figure


def _grid():
    """Four equal-aspect drawings with long two-line titles and a title over them."""
    figure, axes = _figure(9.0, 8.5, nrows=2, ncols=2)
    t = np.linspace(0, 2 * np.pi, 100)
    for k, ax in enumerate(axes.ravel()):
        ax.plot((25 + 3 * k) * np.cos(t), 28 * np.sin(t))
        ax.set_aspect("equal")
        ax.tick_params(labelsize=8)
        ax.set_title(f"gear {k} (stage {k // 2 + 1}, driven): CONCAVE (red)\n"
                     "perimeter 169.65 mm, max pressure-angle dev. 25.5 deg", fontsize=9)
    _suptitle(figure, "Pitch curves: teeth 27 / 27, modules 2.000 / 2.000 mm")
    return figure


def _offsets():
    """Values the formatter scales and offsets ("1e6" over the y axis, "+1e7" under x), with
    a title as wide as the plot."""
    figure, ax = _figure(7.5, 5.0)
    ax.plot(np.linspace(1e7, 1.0001e7, 10), np.linspace(0, 3e6, 10), label="large values")
    ax.set_title("A title as wide as the plot it is over, from one side to the other", size=14)
    ax.set_xlabel("a long label under the axis, out to its right-hand end, where the offset "
                  "of values is", size=11)
    ax.set_ylabel("y")
    _legend_below(figure)
    return figure


KINDS = {"curves": _curves, "events": _events, "twins": _twins, "offsets": _offsets,
         "tall drawing": lambda: _drawing(60.0, 400.0, "A tall drawing, narrower than its "
                                                        "legend and its title"),
         "flat drawing": lambda: _drawing(900.0, 150.0, "A flat drawing"),
         "grid": _grid}


def _decorations(figure) -> list:
    """The texts of a figure: titles, axis labels, the tick labels inside the view, notes on
    the drawing, the legend's labels and the title over the grid."""
    texts = [t for t in figure.texts] + [a for a in figure.artists if isinstance(a, Text)]
    for ax in figure.axes:
        for owner in [ax, *ax.child_axes]:
            texts += [owner.title, owner.xaxis.label, owner.yaxis.label, *owner.texts]
            for axis in (owner.xaxis, owner.yaxis):
                if not axis.get_visible():
                    continue
                texts.append(axis.offsetText)
                low, high = sorted(axis.get_view_interval())
                for tick in axis.get_major_ticks():
                    if low - 1e-9 <= tick.get_loc() <= high + 1e-9:
                        texts += [tick.label1, tick.label2]
    return [t for t in texts if t.get_visible() and t.get_text()]


@pytest.fixture(params=list(KINDS), ids=list(KINDS), scope="module")
def drawn(request):
    figure = KINDS[request.param]()
    data = _png(figure)
    return request.param, figure, data


def assert_texts_clear(figure, name=""):
    """Every text round the axes inside the drawn figure and clear of every other one."""
    renderer = figure.canvas.get_renderer()
    texts = _decorations(figure)
    boxes = [t.get_window_extent(renderer) for t in texts]
    for text, box in zip(texts, boxes):
        assert box.x0 >= -0.5 and box.y0 >= -0.5, (name, text.get_text())
        assert box.x1 <= figure.bbox.width + 0.5, (name, text.get_text())
        assert box.y1 <= figure.bbox.height + 0.5, (name, text.get_text())
    inner = [box.padded(-0.5) for box in boxes]
    for i in range(len(texts)):
        for j in range(i + 1, len(texts)):
            assert not inner[i].overlaps(inner[j]), (name, texts[i].get_text(),
                                                     texts[j].get_text())


def test_every_text_is_inside_the_figure_and_clear_of_the_others(drawn):
    kind, figure, _ = drawn
    assert_texts_clear(figure, kind)


def test_no_text_covers_the_drawing(drawn):
    """Titles, axis labels and the legend stay off every axes' area (tick labels border it)."""
    _, figure, _ = drawn
    renderer = figure.canvas.get_renderer()
    areas = [ax.get_window_extent(renderer).padded(-1.0) for ax in figure.axes]
    legend = foot_legend_of(figure)
    texts = [t for ax in figure.axes for t in (ax.title, ax.xaxis.label, ax.yaxis.label)
             if t.get_text()] + list(figure.texts) + (legend.artists if legend else [])
    for text in texts:
        box = text.get_window_extent(renderer)
        assert not any(box.overlaps(area) for area in areas), getattr(text, "get_text",
                                                                      lambda: text)()


def test_png_is_the_figure_and_is_deterministic(drawn):
    kind, figure, data = drawn
    image = np.asarray(Image.open(io.BytesIO(data)))
    assert image.shape == (round(figure.bbox.height), round(figure.bbox.width), 3)
    assert KINDS[kind] is not None and _png(KINDS[kind]()) == data


@pytest.mark.parametrize("size, wider", [((60.0, 400.0), False), ((900.0, 150.0), True)],
                         ids=["tall", "flat"])
def test_an_equal_aspect_drawing_fills_its_box_in_a_figure_of_its_proportions(size, wider):
    figure = _drawing(*size, "drawing")
    _png(figure)
    ax = figure.axes[0]
    box = ax.get_position(original=True)
    width, height = figure.get_size_inches()
    # the box the layout gave is the drawing's (nothing for the aspect to shrink)
    assert box.height * height / (box.width * width) == pytest.approx(
        ax.get_data_ratio(), rel=1e-6)
    assert height <= 8.0 + 1e-9
    if wider:
        assert width == pytest.approx(7.0) and height < 5.0   # no empty bands above, below
    else:
        assert height == pytest.approx(8.0) and width < 7.0   # nor beside a tall one


def test_legend_samples_are_drawn_in_their_colours_under_the_axes():
    figure, ax = _figure(6.0, 4.0)
    ax.plot([0, 1], [0, 1], color="#ff0000", label="red line")
    _fill(ax, [0, 1, 1], [0, 0, 1], color="#0000ff", label="blue fill")
    _legend_below(figure, ncols=2)
    image = np.asarray(Image.open(io.BytesIO(_png(figure)))).astype(int)
    renderer = figure.canvas.get_renderer()
    foot = round(figure.bbox.height - ax.get_window_extent(renderer).y0)   # rows under axes
    under = image[foot + 30:]        # below the tick labels and the axis' label
    red = (under[..., 0] > 200) & (under[..., 1] < 60) & (under[..., 2] < 60)
    blue = (under[..., 2] > 200) & (under[..., 0] < 60) & (under[..., 1] < 60)
    assert red.sum() > 20 and blue.sum() > 100


@pytest.mark.parametrize("count, ncols, columns", [(5, 2, [3, 2]), (10, 4, [3, 3, 2, 2]),
                                                    (2, 3, [1, 1]), (6, 3, [2, 2, 2])])
def test_legend_fills_its_columns_first_as_matplotlib_does(count, ncols, columns):
    """matplotlib's split: ``divmod(count, ncols)``, the first columns one entry longer."""
    figure, ax = _figure()
    for k in range(count):
        ax.plot([0, 1], [k, k], label=f"entry {k}")
    _legend_below(figure, ncols=ncols)
    _png(figure)
    labels = [a for a in foot_legend_of(figure).artists if isinstance(a, Text)]
    assert [t.get_text() for t in labels] == [f"entry {k}" for k in range(count)]
    renderer = figure.canvas.get_renderer()
    x = [round(t.get_window_extent(renderer).x0) for t in labels]
    y = [round(t.get_window_extent(renderer).y0) for t in labels]
    starts = np.cumsum([0] + columns)
    for column, (a, b) in enumerate(zip(starts[:-1], starts[1:])):
        assert len(set(x[a:b])) == 1                      # one column
        assert y[a:b] == sorted(y[a:b], reverse=True)     # top down
        assert y[a] == y[0]                               # each starts on the first row
        if column:
            assert x[a] > x[a - 1]

# ------------------------------------------------------------------------------------------
# The PNG writer


def test_png_round_trips_exactly_with_its_resolution():
    rgba = np.random.default_rng(15).integers(0, 256, (37, 53, 4), dtype=np.uint8)
    data = _encode_png(rgba[:, :, :3], dpi=DPI)
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    assert struct.unpack(">II", data[16:24]) == (53, 37)
    image = Image.open(io.BytesIO(data))
    assert image.mode == "RGB" and np.array_equal(np.asarray(image), rgba[:, :, :3])
    assert image.info["dpi"] == pytest.approx((DPI, DPI), abs=0.05)
    assert _encode_png(rgba[:, :, :3].copy(), dpi=DPI) == data


def test_png_writer_refuses_what_is_not_rgb():
    with pytest.raises(ValueError, match=r"\(4, 4, 4\)"):
        _encode_png(np.zeros((4, 4, 4), dtype=np.uint8), dpi=DPI)

# ------------------------------------------------------------------------------------------
# The figures of real designs


def _build_figures(path, stages, monkeypatch, case="field", runs=None):
    """``{name: drawn figure}`` of a design built up to ``stages`` (the figures kept; the run
    appended to ``runs``)."""
    import cadgen.pipeline.build
    import cadgen.report.plots.base as base
    from cadgen.params import load_params
    from cadgen.pipeline.figures import figure_jobs

    run = cadgen.pipeline.build._Build(load_params(path), stages, None)
    run.effects, run.case = ["plots"], case
    run.run(cadgen.pipeline.build.STAGE_FUNCTIONS)
    if runs is not None:
        runs.append(run)
    drawn = []

    def keep(figure):
        drawn.append(figure)
        return base._png(figure)

    for module in ("planting", "pricking", "cam", "parts", "housings"):
        monkeypatch.setattr(f"cadgen.report.plots.{module}._png", keep)
    figures = {}
    for name, draw in figure_jobs(run).items():
        draw()
        figures[name] = drawn.pop()
    return figures


DESIGNS = {"planting": ("xin2024-planter.toml", ["kinematics", "metrics", "cam"], 7),
           "pricking": ("kernel-a.toml", ["kinematics", "metrics"], 4)}


@pytest.mark.parametrize("design", list(DESIGNS), ids=list(DESIGNS))
def test_the_figures_of_a_design_keep_their_texts_inside_and_apart(design, monkeypatch):
    from helpers import REFERENCE

    file, stages, count = DESIGNS[design]
    figures = _build_figures(REFERENCE.parent / file, stages, monkeypatch)
    assert len(figures) == count
    for name, figure in figures.items():
        assert_texts_clear(figure, name)


def _words(figure) -> str:
    """Every text of a figure and every legend label, lower case, as one string."""
    texts = [t.get_text() for t in _decorations(figure)]
    for legend in [*figure.legends, *(ax.get_legend() for ax in figure.axes)]:
        if legend is not None:
            texts += [t.get_text() for t in legend.get_texts()]
    return " ".join(texts).lower()


@pytest.mark.parametrize("design, field_only", [("planting", {"absolute_paths.png"}),
                                                ("pricking", {"field_paths.png"})])
def test_a_bench_run_draws_no_soil(design, field_only, monkeypatch):
    """A bench run's report leaves out what needs soil; its figures did show the soil line,
    soil entry and exit, hole widths and absolute paths all the same, and its solids had the
    soil slab (written as solids/ground.stl, in the 3D view and the assembly picture)."""
    from helpers import REFERENCE

    file, stages, count = DESIGNS[design]
    stages, runs = [*stages, "drivetrain", "parts"], []
    field = _build_figures(REFERENCE.parent / file, stages, monkeypatch, runs=runs)
    bench = _build_figures(REFERENCE.parent / file, stages, monkeypatch, case="bench", runs=runs)
    kinds = [{part.kind for part in run.values["parts"].assembly.parts} for run in runs]
    assert "ground" in kinds[0] and kinds[1] == kinds[0] - {"ground"}
    assert "assembly.png" in bench and set(bench) == set(field) - field_only
    # the field figures say these words, so the check below can fail
    assert any("soil" in _words(figure) for figure in field.values())
    for name, figure in bench.items():
        words = _words(figure)
        # (a housing's drawing names its bolt holes: part drawings, no soil to show)
        for word in ("soil", "entry", "exit", "absolute", "s = ",
                     *(() if name.startswith("housing-") else ("hole",))):
            assert word not in words, (name, word)
        assert_texts_clear(figure, name)


def test_the_relative_path_draws_the_arms_one_loop_once(monkeypatch):
    """Both arms' tips trace one loop (the model's arm 2 is arm 1 half a turn on): drawn for
    each, arm 1's lay hidden under arm 2's, with a legend entry for a curve nobody could see."""
    import numpy as np
    from helpers import REFERENCE

    from cadgen.design import build_mechanism
    from cadgen.params import load_params

    # what drawing it once rests on, checked on the model itself
    mechanism = build_mechanism(load_params(REFERENCE))
    phi = np.linspace(0.0, 2.0 * np.pi, 361)
    np.testing.assert_allclose(mechanism.motion(phi, "N", 1).position,
                               mechanism.motion(phi + np.pi, "N", 0).position, atol=1e-9)
    file, stages, _ = DESIGNS["planting"]
    figure = _build_figures(REFERENCE.parent / file, stages, monkeypatch)["relative_path.png"]
    (axes,) = figure.axes
    from matplotlib.text import Text

    from cadgen.report.plots.legend import foot_legend_of

    labels = [a.get_text() for a in foot_legend_of(figure).artists if isinstance(a, Text)]
    assert [label for label in labels if label.startswith("tip N")] == [
        "tip N, both arms (half a turn apart)"]
    assert {"arm 1", "arm 2"} <= set(labels)
    # one curve of the loop (hundreds of points), not two drawn on top of each other
    assert len([line for line in axes.get_lines() if len(line.get_xdata()) > 100]) == 1

