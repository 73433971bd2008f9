"""The clearance sweeps as a picture: distance against carrier angle, with the targets."""

from __future__ import annotations

from cadgen.report.plots.planting import _figure, _png

__all__ = ["clearance_figure"]


def clearance_figure(sweeps: dict) -> bytes:
    """Minimum distance between the solids vs carrier angle, per sweep, the minimum and target
    marked, interference ranges shaded."""
    figure, ax = _figure(8.0, 4.5)
    colours = {"arm_interference": "tab:blue", "ground_clearance": "tab:brown"}
    for key, sweep in sweeps.items():
        samples = sweep["samples"]
        colour = colours.get(key, "k")
        ax.plot(samples["carrier_angle_deg"], samples["distance_mm"], color=colour,
                label=sweep["label"])
        ax.axhline(sweep["target_mm"], color=colour, ls=":", lw=1.0,
                   label=f"target > {sweep['target_mm']:g} mm")
        ax.plot([sweep["carrier_angle_deg"]], [sweep["minimum_mm"]], "o", color=colour)
        ax.annotate(f"{sweep['minimum_mm']:.2f} mm", (sweep["carrier_angle_deg"],
                                                      sweep["minimum_mm"]),
                    textcoords="offset points", xytext=(5, 5), fontsize=8, color=colour)
        for start, end in sweep.get("interference_ranges_deg") or []:
            ax.axvspan(start, end, color="red", alpha=0.2)
    ax.set_xlim(0, 360)
    ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
    ax.set_xlabel("carrier angle (deg, 0 = catching)")
    ax.set_ylabel("minimum distance between the solids (mm)")
    ax.set_title("Clearances of the solids over a revolution (FCL, certified minimum marked)",
                 fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _png(figure)
