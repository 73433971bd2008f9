"""The ground as a closed mesh: a soil slab, flat or a ridge between two furrows, along the travel.

The soil surface does not change along the travel direction x, so one static
slab in the machine's frame serves the whole revolution at any forward speed.
Its top is the soil level (for a ridge: the ridge top); its cross-section in
the (z, y) plane is extruded along x over the mechanism's reach plus a margin.
"""

from __future__ import annotations

import math

import numpy as np

from cadgen.solids.parts import Part

__all__ = ["ground_profile", "ground_part"]


def ground_profile(ground, soil_level: float, z_range, ridge_centre: float) -> np.ndarray:
    """Cross-section of the soil in (z, y), counter-clockwise as seen from +x: (n, 2).

    Flat: a rectangle under ``soil_level``. Ridge: the ridge top (``ridge_top_width``,
    centred at ``ridge_centre``) at the soil level, sides at ``ridge_side_slope_deg``
    down ``ridge_height`` to the furrows (``furrow_width`` each), then the field
    continues level with the furrow bottoms.
    """
    z0, z1 = z_range[0] - ground.margin, z_range[1] + ground.margin
    if ground.profile == "flat":
        bottom = soil_level - ground.thickness
        top = [(z1, soil_level), (z0, soil_level)]
    else:
        furrow = soil_level - ground.ridge_height
        run = ground.ridge_height / math.tan(math.radians(ground.ridge_side_slope_deg))
        half = ground.ridge_top_width / 2
        c = ridge_centre
        z0 = min(z0, c - half - run - ground.furrow_width - ground.margin)
        z1 = max(z1, c + half + run + ground.furrow_width + ground.margin)
        bottom = furrow - ground.thickness
        top = [(z1, furrow), (c + half + run, furrow), (c + half, soil_level),
               (c - half, soil_level), (c - half - run, furrow), (z0, furrow)]
    return np.array([(z0, bottom), (z1, bottom), *top])


def ground_part(ground, soil_level: float, x_range, z_range, *, ridge_centre: float,
                segments: int) -> Part:
    """The ground slab over ``x_range`` (+ margin) as a :class:`Part` fixed to the world."""
    from cadgen.solids.extrude import extrude

    profile = ground_profile(ground, soil_level, z_range, ridge_centre)
    x0, x1 = x_range[0] - ground.margin, x_range[1] + ground.margin
    # extrude the (u, v) = (-z, y) section along w, then turn w onto x: (u, v, w) -> (w, v, -u)
    section = np.column_stack([-profile[:, 0], profile[:, 1]])
    slab = extrude(section, x1 - x0, path="ground", outline_path="ground profile")
    slab = slab.rotate((0.0, 90.0, 0.0)).translate((x0, 0.0, 0.0))
    return Part("ground", "ground", "ground", slab)
