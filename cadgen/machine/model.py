"""What the machine design of a mechanism comes to: shafts, their bearings and seats, hubs.

These records are the interface between the sizing rules (:mod:`cadgen.gears.drivetrain`,
numbers only) and the solids that are built from them (:mod:`cadgen.solids`): the
solids never size anything, the sizing never builds a solid.

Frames and names. Each shaft turns about an axis fixed in one or two housings; an
axis is named as in the mechanism's spec (planting: ``O``, ``A``, ``B``, ``C`` in
gearbox 1, ``C2``, ``D``, ``E`` in gearbox 2; pricking: ``sun``, ``intermediate``,
``planet`` in the gear case). ``xy`` is the axis in the housing's body frame
(:mod:`cadgen.solids.planting`, :mod:`cadgen.solids.pricking`), mm; an axis of
gearbox 1 that exists on both sides of carrier 1 is listed once per side (``side``
1 or 2). Heights ``z`` are measured from the housing's cavity floor (mm, up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

__all__ = ["Bearing", "KeySize", "BearingSeat", "GearMount", "Shaft", "HousingStack",
           "Drivetrain"]


@dataclass(frozen=True)
class Bearing:
    """A deep-groove ball bearing of the catalogue (ISO 15 boundary dimensions), mm and kN."""

    designation: str      # "6004"
    bore: float           # d
    outside: float        # D
    width: float          # B
    dynamic_load_kn: float    # C, basic dynamic load rating
    static_load_kn: float     # C0


@dataclass(frozen=True)
class KeySize:
    """A parallel key and its keyways (DIN 6885-1 / ISO/R 773 form A), mm."""

    width: float          # b
    height: float         # h
    shaft_depth: float    # t1, keyseat depth in the shaft
    hub_depth: float      # t2, keyway depth in the hub
    length: float         # l, from the standard lengths, no longer than the hub

    @property
    def designation(self) -> str:
        return f"parallel key DIN 6885 A {self.width:g} x {self.height:g} x {self.length:g}"


@dataclass(frozen=True)
class BearingSeat:
    """One bearing in one end wall of a housing, and the seat bored for it.

    ``wall`` is ``"floor"`` or ``"roof"`` (the cavity's lower or upper end wall); the
    bearing sits in the wall from its inner face outwards, against a shoulder.
    ``through`` is whether the shaft leaves the housing there (the shoulder then has a
    hole of ``hole_diameter`` for the shaft with running clearance; otherwise the seat
    is blind).
    """

    shaft: str
    housing: str
    side: int
    xy: tuple
    wall: str
    bearing: Bearing
    seat_diameter: float      # bore of the seat: bearing OD + the process's fit
    through: bool
    hole_diameter: float      # through: shaft + running clearance; blind: 0
    load_n: float             # radial load on this bearing (design load x service factor)
    speed_rpm: float          # mean speed of the inner ring relative to the housing
    life_h: float             # ISO 281 basic rating life L10h; inf when the load is 0
    life_min_h: float
    count: int = 1            # bearings side by side in the seat (2: a pair, face to face)
    load_source: str = "assumed tip force"   # or the dynamics' (machine.cycle_loads): then
    peak_load_n: float | None = None         # load_n is ISO 281's P_eq, this the turn's peak

    @property
    def life_passed(self) -> bool:
        return self.life_h >= self.life_min_h

    @property
    def depth(self) -> float:
        """How deep the seat is bored: its bearings' widths side by side (mm)."""
        return self.count * self.bearing.width


@dataclass(frozen=True)
class GearMount:
    """A gear on a shaft: where it sits and what it loads the shaft with."""

    gear: str                 # the gear's name, as in the gear train ("central", "idler 1", ...)
    z_bottom: float           # from the housing's cavity floor, mm
    face_width: float
    torque_nm: float          # transmitted through its hub (0 for an idler)
    radial_load_n: float      # resultant of its mesh forces on the shaft (N)
    hub_bore: float           # bore diameter (nominal = the shaft's)
    key: KeySize | None       # None: a D-flat (small shafts) or a fixed gear
    flat_depth: float         # D-flat depth from the shaft surface, mm (0: none)
    bore_allowance: float     # the hub bore's diametral allowance from the process's fit, mm
    housing: str = ""         # the housing it turns in, when not its shaft's ("": the shaft's)
    bearing: Bearing | None = None   # runs free on the shaft on two of these (an idler of
    #                                  another set): hub bore = their OD + the seat's fit
    speed_rpm: float = 0.0    # a free gear's speed relative to its shaft (its bearings')
    life_h: float = math.inf  # ... and their L10h under half its radial load each


@dataclass(frozen=True)
class Shaft:
    """One shaft: its size, what it carries, its bearings, and how its size was chosen."""

    name: str
    housing: str              # the housing whose floor holds its lower bearing
    side: int
    xy: tuple
    diameter: float           # chosen (preferred size, or given in the file)
    required_diameter: float  # from torque and bending with the safety factor
    given: bool               # the file gave the diameter
    torque_nm: float          # largest torque it transmits (design load x service factor)
    bending_nmm: float        # largest bending moment between its bearings, N mm
    speed_rpm: float          # mean speed relative to its housing
    mounts: tuple             # GearMount, ...
    seats: tuple              # BearingSeat, ... (lower first)
    extends_below: float      # beyond the floor's outer face, mm (0: ends in a blind seat)
    extends_above: float      # beyond the roof's outer face, mm
    note: str = ""            # what it drives or is driven by beyond the housing
    bore: float = 0.0         # a hollow shaft's bore (mm): another shaft turns inside it
    ends: tuple | None = None  # (z_bottom, z_top) from its housing's cavity floor (mm), when
    #                            it reaches into another housing; None: from its seats
    flange: dict | None = None  # a hollow shaft's bolted flange carrying a housing
    coupling_key: KeySize | None = None   # the key of its stub (a sprocket or coupling on it)
    load_source: str = "assumed tip force"   # what its torque, bending and keys' loads are
    sized_from: str = "assumed tip force"    # what its diameter and bearings were chosen from

    @property
    def strength_passed(self) -> bool:
        return self.diameter >= self.required_diameter - 1e-9


@dataclass(frozen=True)
class HousingStack:
    """A housing's axial stack: end walls thick enough for its bearing seats, cavity height."""

    housing: str
    floor_wall: float         # cavity floor's wall: the thicker of the side wall and the deepest
    roof_wall: float          #   seat in it plus its shoulder
    cavity_height: float
    parting_z: float          # the base/cover joint, from the cavity floor
    layers: tuple             # ((z_bottom, face_width), ...) of the gear layers, from the floor


@dataclass(frozen=True)
class Drivetrain:
    """Every shaft, bearing seat and housing stack of a mechanism, with the rules used."""

    mechanism: str
    shafts: tuple
    stacks: dict              # housing name -> HousingStack
    process: str
    rules: dict = field(default_factory=dict)   # the formulas and constants, for the report
    problems: tuple = ()      # kinematics.errors.Problem of failing checks (life, strength, rim)
    drive: object = None      # cadgen.gears.drive.DriveDesign of the frame's two pairs, or None
    bases: dict = field(default_factory=dict)   # housing -> z of its cavity floor (mm), in
    #                                              the first housing's frame
    fixings: dict = field(default_factory=dict)   # part -> its fixing (machine.fixings):
    #                                                 the planter's and rocker's keyed hubs,
    #                                                 the cam's screws, the needle's clamp
    retention: tuple = ()   # machine.retention.ShaftRetention of each shaft, as shafts

    def seats(self, housing: str) -> list:
        """The bearing seats of one housing, every side; a seat two shafts' records share (the
        inner shafts C2 of both arms end in gearbox 2's roof, one housing part per arm) once."""
        out, seen = [], set()
        for shaft in self.shafts:
            for seat in shaft.seats:
                key = (seat.shaft, seat.wall, tuple(round(float(v), 9) for v in seat.xy))
                if seat.housing == housing and key not in seen:
                    seen.add(key)
                    out.append(seat)
        return out

    def shaft_of_gear(self, gear: str) -> tuple:
        """``(shaft, mount)`` carrying the named gear (side 1 when it exists on both sides)."""
        for shaft in sorted(self.shafts, key=lambda s: s.side):
            for mount in shaft.mounts:
                if mount.gear == gear:
                    return shaft, mount
        raise KeyError(f"no shaft carries the gear {gear!r}")
