"""What a gear's material and process allow its teeth: the endurance stresses and elastic data.

The tooth strength (:mod:`cadgen.gears.strength`) compares a tooth's root stress with its
bending endurance ``sigma_FE`` and its flank's Hertz stress with its pitting endurance
``sigma_Hlim``. Materials are named as the bill names them (:mod:`cadgen.machine.fits`:
``"steel C45"``, ``"steel S355"``, ``"PETG"``, ...); the process that cut the flanks sets the
roughness part of the contact's life factors.

Sources and the choices made (each row's ``source`` says it in the report):

- **Steels: ISO 6336-5:2016, Table 1** (``sigma_lim = A x + B``, quality MQ: the grade a
  workshop's certified bar and normal heat treatment give). ``sigma_FE = Y_ST sigma_Flim`` with
  ``Y_ST = 2`` (ISO 6336-3). The hardness is the low end of the delivery condition, so the
  figures are not flattered:

  - C45+N (normalised; EN 10083-2 gives it no hardness, its Rm >= 620 MPa is about 195 HV by
    ISO 18265; taken as 190 HV), through-hardened carbon steel (row 22 and 28):
    ``sigma_Hlim = 0.925 x 190 + 360 = 535.75``, ``sigma_Flim = 0.240 x 190 + 163 = 208.6``;
  - S355 (structural, normalised low-carbon wrought St; Rm >= 470 MPa, about 150 HBW), rows 1
    and 5: ``sigma_Hlim = 1.000 x 150 + 190 = 340``, ``sigma_Flim = 0.455 x 150 + 69 = 137.25``;
  - 42CrMo4+QT (a stronger choice a designer may name; 300 HV), alloy steel, rows 25 and 31:
    ``sigma_Hlim = 1.313 x 300 + 373 = 766.9``, ``sigma_Flim = 0.425 x 300 + 187 = 314.5``.

  Elastic: E = 206 000 MPa, nu = 0.3 (ISO 6336-2's steel). Flanks as hobbed, shaped, wire-EDM
  or laser cut (Rz above 4 um): ``Z_L Z_V Z_R = 0.85``, ISO 6336-2 method C.
- **Aluminium** (indicative): no ISO 6336-5 rows. ``sigma_FE`` is taken as the unnotched
  rotating-bending fatigue strength at 5e8 cycles (completely reversed, so conservative for
  the tooth root's pulsating stress): EN AW-7075-T6 159 MPa (Aluminum Association / ASM
  handbook figure); EN AW-6082-T6 is taken as the 96.5 MPa of EN AW-6061-T6, the nearest
  alloy with a published figure (6082-T6 is the stronger). Aluminium flanks have no published
  pitting endurance of the ISO kind: their contact is not rated (``sigma_Hlim`` None; the
  report says so). E = 71 700 / 70 000 MPa, nu = 0.33.
- **Printed polymers** (indicative): VDI 2736-2 tabulates moulded POM, PA66, PBT, PEEK, not
  printed PETG or PA12. Its method (root stress ``Ft / (b m) Y_Fa Y_Sa Y_eps``, Hertz flank
  stress, against endurance stresses from gear tests) is used with endurance stresses derived
  by a stated rule from the printed material's in-plane tensile strength ``Rm`` (the gears
  are printed flat, so the root's bending stress runs along the layers): ``sigma_FE = 0.4 Rm``
  (unfilled thermoplastics' bending fatigue strength at 1e7 cycles and room temperature is
  0.3-0.5 of their tensile strength; VDI 2736-2's moulded PA66 and POM root endurances are of
  that order) and ``sigma_Hlim = 0.8 Rm``. PETG printed: Rm 50 MPa, E 2 000 MPa, nu 0.38
  (filament makers' data sheets, printed specimens in XY); PA12 printed (SLS/MJF): Rm 48 MPa,
  E 1 700 MPa, nu 0.4 (EOS PA 2200 and HP PA 12 data sheets, XY). Test a printed pair before
  relying on these.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

__all__ = ["GearMaterial", "GEAR_MATERIALS", "gear_material", "STEEL_ROUGH_FLANKS",
           "YST", "IDLER_BENDING_FACTOR"]

#: ISO 6336-3's stress correction factor of the reference test gear: ``sigma_FE = Y_ST sigma_Flim``.
YST = 2.0
#: ISO 6336-2 method C, ``Z_L Z_V Z_R`` of flanks hobbed, shaped or otherwise cut (Rz > 4 um).
STEEL_ROUGH_FLANKS = 0.85
#: ISO 6336-5: a tooth loaded on both flanks in turn (an idler, whose two meshes bend it each
#: way) endures 0.7 of the pulsating root stress.
IDLER_BENDING_FACTOR = 0.7


@dataclass(frozen=True)
class GearMaterial:
    """A gear material's allowables and elastic data (stresses in MPa).

    Attributes
    ----------
    name : str
        As the bill names it (``"steel C45"``).
    bending_endurance : float
        ``sigma_FE``: the tooth-root stress of the reference test gear the tooth endures
        (``Y_ST sigma_Flim`` for steels).
    contact_endurance : float or None
        ``sigma_Hlim``: the flank's pitting endurance; None where no published figure exists
        (the contact is then not rated).
    youngs_modulus, poisson_ratio : float
        For the elasticity factor ``Z_E``.
    surface_factor : float
        ``Z_L Z_V Z_R`` the flanks' roughness and lubrication take off ``sigma_Hlim``.
    source : str
        Where the figures come from.
    indicative : bool
        True where the figures follow a stated rule rather than a gear standard's table.
    """

    name: str
    bending_endurance: float
    contact_endurance: float | None
    youngs_modulus: float
    poisson_ratio: float
    surface_factor: float
    source: str
    indicative: bool = False

    def as_dict(self) -> dict:
        return asdict(self)


def _steel(name, hardness, contact, bending, source):
    """An ISO 6336-5 row pair: ``(A, B)`` of contact and of bending at ``hardness``."""
    return GearMaterial(name, YST * (bending[0] * hardness + bending[1]),
                        contact[0] * hardness + contact[1], 206000.0, 0.3, STEEL_ROUGH_FLANKS,
                        source)


_ISO = "ISO 6336-5:2016 Table 1, quality MQ"
_POLYMER_RULE = ("indicative: VDI 2736 method, endurances by rule from the printed XY tensile "
                 "strength Rm (sigma_FE = 0.4 Rm, sigma_Hlim = 0.8 Rm)")
#: Every gear material the build knows, by the bill's name.
GEAR_MATERIALS = {m.name: m for m in (
    _steel("steel C45", 190.0, (0.925, 360.0), (0.240, 163.0),
           f"{_ISO}, through-hardened carbon steel V, C45+N at 190 HV"),
    _steel("steel S355", 150.0, (1.000, 190.0), (0.455, 69.0),
           f"{_ISO} (ML/MQ), normalised low-carbon wrought steel St, S355 at 150 HBW"),
    _steel("steel 42CrMo4+QT", 300.0, (1.313, 373.0), (0.425, 187.0),
           f"{_ISO}, through-hardened alloy steel V, 42CrMo4+QT at 300 HV"),
    GearMaterial("aluminium EN AW-7075", 159.0, None, 71700.0, 0.33, 1.0,
                 "indicative: sigma_FE = rotating-bending fatigue strength at 5e8 cycles of "
                 "7075-T6 (Aluminum Association); no pitting endurance published", True),
    GearMaterial("aluminium EN AW-6082", 96.5, None, 70000.0, 0.33, 1.0,
                 "indicative: sigma_FE = rotating-bending fatigue strength at 5e8 cycles of "
                 "6061-T6 (Aluminum Association), 6082-T6's nearest published; no pitting "
                 "endurance published", True),
    GearMaterial("PETG", 0.4 * 50.0, 0.8 * 50.0, 2000.0, 0.38, 1.0,
                 f"{_POLYMER_RULE}; printed PETG Rm 50 MPa (filament data sheets)", True),
    GearMaterial("PA12", 0.4 * 48.0, 0.8 * 48.0, 1700.0, 0.4, 1.0,
                 f"{_POLYMER_RULE}; SLS/MJF PA12 Rm 48 MPa (EOS PA 2200, HP PA 12 data "
                 "sheets)", True),
)}


def gear_material(name: str) -> GearMaterial:
    """The :class:`GearMaterial` the bill calls ``name`` (an aluminium named only
    ``"aluminium"`` is taken as EN AW-6082, the housings' alloy)."""
    if name == "aluminium":
        name = "aluminium EN AW-6082"
    try:
        return GEAR_MATERIALS[name]
    except KeyError:
        raise ValueError(f"no tooth-strength allowables for the gear material {name!r} "
                         f"(known: {', '.join(GEAR_MATERIALS)})") from None
