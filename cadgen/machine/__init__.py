"""Machine design: shafts, bearings, keys and fits a workshop can make (numbers only, no solids).

Modules
-------
model
    The records the sizing hands to the solids: :class:`Bearing`, :class:`KeySize`,
    :class:`BearingSeat`, :class:`GearMount`, :class:`Shaft`, :class:`HousingStack`,
    :class:`Drivetrain`.
catalogue
    The tables (``data/*.csv``, sources in ``data/README.md``): deep-groove ball
    bearings, DIN 6885 keys, ISO 273 clearance holes, ISO 4762 screws, ISO 4032 nuts,
    ISO 7089 washers.
fits
    An ISO 286-1 subset (IT6-IT9; H, h, k, g, js) and each manufacturing process's
    allowances, backlash and materials (:func:`process_fits`).
loads
    The torque chain from the tool's tip load to every gear, and the shafts' speeds.
layouts
    Where each axis is and what it carries, each housing's cavity, the housings' stack.
fastening
    Gears running free on their bearings, carrying flanges, stub couplings: sizes and checks.
shafts
    The beam on two bearings, the diameter from torque and bending, keys and D-flats.
bearings
    ISO 281 basic rating life and the choice of a bearing from the catalogue.
drivetrain
    Everything together for a mechanism: :func:`drivetrain`, :func:`drivetrain_report`.

Only the records, the catalogue, the fits and the bearing life (standard library) are
imported here. The drivetrain (numpy, the gears, the kinematics) is imported from its
module, ``from cadgen.machine.drivetrain import drivetrain, drivetrain_report``: the
package does not re-export the function, whose name is its module's.
"""

from cadgen.machine.bearings import l10_hours, select_bearing
from cadgen.machine.catalogue import CatalogueError
from cadgen.machine.fits import ProcessFits, deviation, process_fits
from cadgen.machine.model import (Bearing, BearingSeat, Drivetrain, GearMount, HousingStack,
                                  KeySize, Shaft)

__all__ = ["Bearing", "KeySize", "BearingSeat", "GearMount", "Shaft", "HousingStack",
           "Drivetrain", "CatalogueError", "ProcessFits", "deviation", "process_fits",
           "l10_hours", "select_bearing"]

