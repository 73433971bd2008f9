"""Cold-coiled helical compression springs of round wire, designed and checked by EN 13906-1.

The duckbill's return spring has to push with at least a required force ``F1`` when the
mechanism is at rest (the installed length ``L1``) and travels a known stroke ``h`` to the
working length ``L2 = L1 - h``. :func:`design_compression_spring` tries the EN 10270-1 DH wires
from the thinnest up; for each it takes the smallest mean diameter that clears the guide rod,
the most active coils that fit the room (the softest spring: its force changes least over the
stroke) and keeps the first that passes every check:

* rate ``R = G d^4 / (8 D^3 n)`` with ``G = 81 500 MPa`` (EN 13906-1, Table 2, for EN 10270-1
  wire);
* stress at the largest force, corrected for the coil's curvature by Wahl's factor
  ``k = (4w - 1) / (4w - 4) + 0.615 / w`` (``w = D / d``),
  ``tau_k2 = k 8 D F2 / (pi d^3)``, against EN 13906-1's permissible ``0.5 Rm`` with ``Rm``
  the wire's minimum tensile strength (EN 10270-1 DH); Wahl's factor is a little above the
  standard's own Bergstraesser factor, so the check errs on the safe side;
* solid length ``Lc = (n + 2) d`` (closed and ground ends, ``n_t = n + 2``), and the least sum
  of gaps between active coils at ``L2``, ``Sa = 1.5 (0.0015 D^2 / d + 0.1 d) n`` (the
  standard's rule, times 1.5 for a spring worked dynamically as a cam spring is);
* index ``4 <= w <= 12`` (EN 13906-1's formulas hold to 20; spring makers coil up to about 12
  without the coils tangling or the diameter's tolerance, EN 15800, widening) and ``n >= 2``;
* buckling: EN 13906-1's critical deflection
  ``sK = L0 0.5 / (1 - G/E) [1 - sqrt(1 - (1 - G/E) / (0.5 + G/E) (pi D / (nu L0))^2)]``
  with ``E = 206 000 MPa`` and ``nu = 0.5`` (both ends seated on parallel faces): no root
  means the spring cannot buckle; else ``sK`` must exceed the largest deflection.

Not checked: fatigue (the stroke's stress range against the standard's Goodman diagram) and
surge; both are reported as the numbers a spring maker asks for.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

__all__ = ["CompressionSpring", "design_compression_spring", "wahl_factor", "SHEAR_MODULUS",
           "YOUNG_MODULUS", "SEATING_COEFFICIENT", "STRESS_RATIO"]

#: EN 13906-1, Table 2: patented cold-drawn unalloyed wire (EN 10270-1), MPa.
SHEAR_MODULUS = 81_500.0
YOUNG_MODULUS = 206_000.0
#: Seating coefficient nu of EN 13906-1's buckling rule: both ends on parallel, guided faces.
SEATING_COEFFICIENT = 0.5
#: EN 13906-1's permissible shear stress under static load, as a fraction of Rm.
STRESS_RATIO = 0.5
#: The spring index range taken: EN 13906-1's formulas hold for 4..20, spring makers prefer
#: to coil no more than about 12.
INDEX_RANGE = (4.0, 12.0)
#: The gap-sum rule's factor for a dynamically worked spring (EN 13906-1: 1.5 x the static).
DYNAMIC_GAP_FACTOR = 1.5


def wahl_factor(index: float) -> float:
    """Wahl's stress correction factor of a coil of index ``w = D / d``."""
    w = float(index)
    return (4 * w - 1) / (4 * w - 4) + 0.615 / w


@dataclass(frozen=True)
class CompressionSpring:
    """A compression spring and its checks (mm, N, MPa)."""

    wire: float                  # d
    mean_diameter: float         # D
    active_coils: float          # n
    total_coils: float           # n_t = n + 2 (closed, ground ends)
    rate: float                  # R, N/mm
    free_length: float           # L0
    installed_length: float      # L1: the mechanism at rest
    working_length: float        # L2: at the end of the stroke
    solid_length: float          # Lc
    least_working_length: float  # Ln = Lc + Sa: L2 must not be shorter
    preload: float               # F1 at L1
    force_max: float             # F2 at L2
    required_preload: float      # what F1 had to reach
    stroke: float                # L1 - L2
    index: float                 # w = D / d
    wahl: float
    stress_max: float            # tau_k2, corrected, at F2
    stress_solid: float          # uncorrected, at the solid length
    tensile_strength: float      # Rm min of the wire (EN 10270-1 DH)
    stress_allowed: float        # 0.5 Rm
    buckling_deflection: float | None   # sK, None: the spring cannot buckle

    @property
    def utilisation(self) -> float:
        """``tau_k2 / (0.5 Rm)``: below 1 the spring holds its largest force."""
        return self.stress_max / self.stress_allowed

    @property
    def inside_diameter(self) -> float:
        return self.mean_diameter - self.wire

    @property
    def outside_diameter(self) -> float:
        return self.mean_diameter + self.wire

    @property
    def designation(self) -> str:
        """The line a spring maker orders from."""
        return (f"compression spring EN 13906-1, wire EN 10270-1-DH {self.wire:g} mm, "
                f"D {self.mean_diameter:.1f} mm, n {self.active_coils:g} "
                f"(n_t {self.total_coils:g}), L0 {self.free_length:.1f} mm, "
                f"closed and ground ends")

    def as_dict(self) -> dict:
        out = asdict(self)
        out.update(utilisation=self.utilisation, inside_diameter=self.inside_diameter,
                   outside_diameter=self.outside_diameter, designation=self.designation,
                   buckles=self.buckling_deflection is not None
                   and self.buckling_deflection <= self.free_length - self.working_length)
        return out


def _buckling_deflection(free_length: float, mean_diameter: float) -> float | None:
    ratio = SHEAR_MODULUS / YOUNG_MODULUS
    slenderness = math.pi * mean_diameter / (SEATING_COEFFICIENT * free_length)
    radicand = 1.0 - (1.0 - ratio) / (0.5 + ratio) * slenderness**2
    if radicand < 0.0:
        return None   # the spring cannot buckle, however far it is compressed
    return free_length * 0.5 / (1.0 - ratio) * (1.0 - math.sqrt(radicand))


def _spring(d, D, n, rm, preload_needed, stroke, room):
    """The spring of wire ``d``, mean diameter ``D`` and ``n`` active coils, installed with at
    least ``preload_needed`` in ``room`` mm (its installed length)."""
    rate = SHEAR_MODULUS * d**4 / (8 * D**3 * n)
    solid = (n + 2) * d
    gaps = DYNAMIC_GAP_FACTOR * (0.0015 * D**2 / d + 0.1 * d) * n
    installed = float(room)
    preload_travel = preload_needed / rate
    free = installed + preload_travel
    working = installed - stroke
    force_max = rate * (free - working)
    index = D / d
    wahl = wahl_factor(index)
    stress = wahl * 8 * D * force_max / (math.pi * d**3)
    stress_solid = 8 * D * rate * (free - solid) / (math.pi * d**3)
    return CompressionSpring(
        wire=d, mean_diameter=D, active_coils=n, total_coils=n + 2, rate=rate, free_length=free,
        installed_length=installed, working_length=working, solid_length=solid,
        least_working_length=solid + gaps, preload=rate * preload_travel,
        force_max=force_max, required_preload=preload_needed, stroke=stroke, index=index,
        wahl=wahl, stress_max=stress, stress_solid=stress_solid, tensile_strength=rm,
        stress_allowed=STRESS_RATIO * rm,
        buckling_deflection=_buckling_deflection(free, D))


def design_compression_spring(preload: float, stroke: float, room: float, *,
                              inside_min: float, outside_max: float, wires=None):
    """The lightest spring that pushes ``preload`` N at ``room`` mm and travels ``stroke`` mm.

    Parameters
    ----------
    preload : float
        The force (N) the spring must give at its installed length, at least.
    stroke : float
        mm the spring is compressed further in work.
    room : float
        Its installed length (mm): the distance between its seats at rest.
    inside_min, outside_max : float
        Its coils must clear a guide rod (inside diameter at least ``inside_min``) and fit its
        bore (outside diameter at most ``outside_max``), mm.
    wires : sequence of (d, Rm_min, Rm_max), optional
        EN 10270-1 wires to try (default: :func:`cadgen.machine.pins.spring_wires`).

    Returns
    -------
    (CompressionSpring or None, str)
        The spring, or None and why no wire gave one.
    """
    if wires is None:
        from cadgen.machine.pins import spring_wires

        wires = spring_wires()
    preload, stroke, room = float(preload), float(stroke), float(room)
    if not (preload > 0 and stroke > 0 and room > stroke):
        raise ValueError(f"a spring needs a positive preload, stroke and room longer than the "
                         f"stroke, not {preload!r} N, {stroke!r} mm, {room!r} mm")
    why = "no EN 10270-1 DH wire in the table"
    for d, rm, _ in wires:
        D = max(inside_min + d, INDEX_RANGE[0] * d)
        if D + d > outside_max + 1e-9 or D / d > INDEX_RANGE[1]:
            why = (f"no wire fits between the {inside_min:g} mm rod and the {outside_max:g} mm "
                   f"bore with an index in {INDEX_RANGE}")
            continue
        gap_per_coil = DYNAMIC_GAP_FACTOR * (0.0015 * D**2 / d + 0.1 * d)
        # the most coils whose least working length still fits at the end of the stroke,
        # in half coils
        coils = math.floor(2 * (room - stroke - 2 * d) / (d + gap_per_coil)) / 2
        if coils < 2:
            why = f"fewer than two active coils of {d:g} mm wire fit in {room:.1f} mm"
            continue
        spring = _spring(d, D, coils, rm, preload, stroke, room)
        if spring.utilisation > 1.0:
            why = (f"the thickest wire that fits is stressed to {spring.utilisation:.2f} x "
                   f"0.5 Rm at {spring.force_max:.1f} N")
            continue
        buckle = spring.buckling_deflection
        if buckle is not None and buckle <= spring.free_length - spring.working_length:
            why = f"a {d:g} mm wire spring would buckle ({buckle:.1f} mm)"
            continue
        return spring, ""
    return None, why
