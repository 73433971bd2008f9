"""The batched ticks (cadgen.report.plots.ticks) draw the same pixels as matplotlib's Tick
objects: each figure is drawn twice, with and without them, and the canvases compared."""

import matplotlib
import numpy as np
import pytest

from cadgen.report.plots import base
from cadgen.report.plots.layout import fit_layout
from cadgen.report.plots.ticks import batch_ticks


def _pixels(build, batched):
    figure = build()
    with matplotlib.rc_context(base._DRAWING):
        fit_layout(figure, dpi=base.DPI)
        if batched:
            batch_ticks(figure)
        figure.canvas.draw()
    return np.asarray(figure.canvas.buffer_rgba()).copy()


def _plain():
    figure, ax = base._figure(6.0, 4.0)
    x = np.linspace(-37.0, 413.0, 300)
    ax.plot(x, np.sin(x / 40), label="sine")
    ax.set_xlabel("angle (deg)")
    ax.set_ylabel("value")
    ax.set_title("plain")
    ax.grid(alpha=0.3)
    base._legend_below(figure)
    return figure


def _twin_secondary_shared():
    figure, (top, bottom) = base._figure(7.0, 6.0, nrows=2, sharex=True)
    x = np.linspace(0.0, 360.0, 200)
    top.plot(x, np.cos(np.radians(x)))
    twin = top.twinx()
    twin.plot(x, 50 * np.sin(np.radians(x)), ls="--")
    twin.set_ylabel("right")
    bottom.plot(x, x ** 1.5)
    base._event_ticks(top, {"entry": 165.0, "lowest": 188.0, "seedling cleared": 236.0},
                      rotation=30)
    top.tick_params(labelbottom=True, labelsize=7)
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
        ax.set_xlim(0, 360)
    return figure


def _equal_inverted():
    figure, (plan, cut) = base._figure(8.0, 8.0, ncols=2)
    t = np.linspace(0, 2 * np.pi, 400)
    base._fill(plan, 120 * np.cos(t), 45 * np.sin(t), facecolor="0.8")
    cut.plot([-10, 30], [-5, 12])
    for ax in (plan, cut):
        ax.set_aspect("equal", adjustable="box")
        ax.grid(alpha=0.2)
    plan.invert_yaxis()
    return figure


@pytest.mark.parametrize("build", [_plain, _twin_secondary_shared, _equal_inverted])
def test_batched_ticks_draw_the_same_pixels(build):
    assert np.array_equal(_pixels(build, False), _pixels(build, True))


def test_axis_with_offset_text_keeps_matplotlibs_ticks():
    figure, ax = base._figure(5.0, 3.0)
    ax.plot([1e7, 1e7 + 5], [0, 1])
    fit_layout(figure, dpi=base.DPI)
    before = ax.xaxis.get_major_locator()
    batch_ticks(figure)
    assert ax.xaxis.get_major_locator() is before      # "+1e7": left to matplotlib
    assert ax.yaxis.get_major_locator() is not before
