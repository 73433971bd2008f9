"""The bought items a joint is made with, from the machine design's records.

Each function turns one record of :mod:`cadgen.machine` (a bearing, a key, a bolted flange,
the pricking case's sprocket) into the :class:`~cadgen.assembly.graph.Item` rows a joint
carries; the bill of materials sums them over the joints of the assembly model
(:meth:`~cadgen.assembly.graph.AssemblyModel.bought`). The words are the ones a buyer
orders by: the standard, the size and the strength class.
"""

from __future__ import annotations

from cadgen.assembly.graph import Item

__all__ = ["bearing_item", "key_item", "bolt_set", "bolted_flange_items", "screw_items",
           "sprocket_items", "dowel_items"]


def bearing_item(bearing, count: int) -> Item:
    """``count`` sealed deep-groove ball bearings (``-2Z``) of ``bearing``'s catalogue row."""
    name = (f"deep-groove ball bearing {bearing.designation}-2Z "
            f"({bearing.bore:g} x {bearing.outside:g} x {bearing.width:g} mm)")
    return Item("bearing", name, bearing.designation, int(count))


def key_item(key) -> Item:
    """One DIN 6885 parallel key."""
    return Item("key", key.designation, key.designation, 1)


def bolt_set(thread: str, grip: float) -> dict:
    """The screw, nut and washers that clamp ``grip`` mm of flange: designations and length.

    The screw is the shortest ISO 4762 standard length through the grip, two washers
    (ISO 7089), the nut (ISO 4032) and two thread pitches beyond it.
    """
    from cadgen.machine.catalogue import nut, screw_length, socket_screw, washer

    nut_row, washer_row = nut(thread), washer(thread)
    # the screw's end stands at least two thread pitches out of the nut
    needed = (grip + 2 * float(washer_row["h"]) + float(nut_row["m"])
              + 2 * socket_screw(thread)["pitch"])
    length = screw_length(thread, needed)
    size = thread.removeprefix("M")
    return {"screw": f"ISO 4762 {thread} x {length:g} - 8.8", "screw_length": length,
            "nut": f"ISO 4032 {thread} - 8", "washer": f"ISO 7089 {size} - 200 HV",
            "needed_length": needed}


def bolted_flange_items(thread: str, grip: float, bolts: int) -> tuple[Item, ...]:
    """``bolts`` through-bolted sets over ``grip`` mm: a screw, a nut and two washers each."""
    if bolts < 1:
        return ()
    names = bolt_set(thread, grip)
    return (Item("socket head cap screw", names["screw"], names["screw"], bolts),
            Item("hexagon nut", names["nut"], names["nut"], bolts),
            Item("plain washer", names["washer"], names["washer"], 2 * bolts))


def screw_items(thread: str, clamped: float, count: int, length: float | None = None
                ) -> tuple[Item, ...]:
    """``count`` socket head cap screws through ``clamped`` mm into a tapped hole: the shortest
    ISO 4762 length that engages one and a half diameters of thread (or ``length``, chosen by
    the fixing)."""
    from cadgen.machine.catalogue import screw_length

    if length is None:
        length = screw_length(thread, float(clamped) + 1.5 * float(thread.removeprefix("M")))
    screw = f"ISO 4762 {thread} x {length:g} - 8.8"
    return (Item("socket head cap screw", screw, screw, int(count)),)


def sprocket_items(held: dict) -> tuple[Item, ...]:
    """The pricking case's chain sprocket (a plate wheel, bored and drilled to the drawing) and
    the screws that hold it to the case's floor."""
    sprocket = held["sprocket"]
    chain = held["chain"]["designation"]
    wheel = (f"chain sprocket ISO 606 {chain}, plate wheel, z = {sprocket['teeth']}, "
             f"bored {sprocket['bore']:.1f} mm, {sprocket['bolts']} x {sprocket['bolt']} holes "
             f"on a {2 * sprocket['bolt_circle_radius']:.1f} mm circle")
    return ((Item("sprocket", wheel, f"ISO 606 {chain} z{sprocket['teeth']}", 1),)
            + screw_items(sprocket["bolt"], sprocket["width"], int(sprocket["bolts"])))


def dowel_items(housing) -> tuple[Item, ...]:
    """A split housing's dowel pins (ISO 8734, :func:`cadgen.machine.fixings.dowel_pins`)."""
    from cadgen.machine.fixings import dowel_pins

    low, high = housing.flange_z
    pins = dowel_pins(housing.bolt_size, high - low)
    return (Item("dowel pin", f"dowel pin {pins['designation']} ({pins['fit']})",
                 pins["designation"], len(housing.dowels)),)
