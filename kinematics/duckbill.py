"""The duckbill planter's linkage: blades, push rod and cam lever, in the planter's frame.

Planter frame: origin at E (the planet-gear axis, where the cam sits), x along
``u(Psi)``, y along ``u(Psi + 90 deg)``; so ``P1 = (-L1, 0)`` and the duckbill
tip ``N = (-L1, -L2)``, the duckbill axis being the line ``x = -L1``.

Blades (vector loop O1-J-P2, drawn for the right blade; the left one mirrors it
about the axis): each blade, ``blade_length`` long, is hinged at
``O1 = (-L1 + e, -L2 + l_b cos d0)`` with ``e = l_b sin d0``, so that closed
(opening ``beta = 0``) the two tips meet at N with the closed half-angle ``d0``.
Opening by ``beta`` swings each tip outwards: the mouth is
``w = 2 l_b (sin d0 - sin(d0 - beta))`` wide. A crank O1-J of length ``c``
(pointing at the axis when closed) is joined by a link J-P2 of length ``ell`` to
the push-rod end P2 on the axis, shared by both blades: pushing P2 down opens them.

Lever (H-I-G, a bell crank): pivot ``H = (-r_b, -l_HI)``, roller centre I at
``l_HI`` above H (so at rest I sits on the cam's base circle ``r_b`` with the lever
perpendicular to E-I: zero pressure angle in the dwells) and the push-rod pin G
at ``l_HG`` behind H, on the duckbill axis by default (``l_HG = L1 - r_b``).
Turning the lever by ``lam`` (counter-clockwise) moves the roller outwards and G
down by ``l_HG sin(lam)``; G drives the push rod through a pin in a slot, so the
push-rod stroke ``s`` needs the lever angle ``asin(s / l_HG)``. The cam rise is
the roller's radial displacement that follows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import DesignError, Problem

__all__ = ["DuckbillLinkage"]

#: The lever may turn at most this much (rad): beyond it the pin-in-slot drive
#: and the roller's contact lose their geometry.
MAX_LEVER_ANGLE = np.radians(45.0)
#: The blades may open at most this much (rad): further, the blade tips swing up
#: into the soil wall and the push rod's links lose their leverage.
MAX_OPENING = np.radians(45.0)


@dataclass(frozen=True)
class DuckbillLinkage:
    """The duckbill planter's blade and lever linkage (lengths in mm, angles in rad).

    Build with :meth:`design`, which checks the geometry and derives the opening
    angle from the pot; the attributes below are then consistent.
    """

    L1: float
    L2: float
    blade_length: float
    closed_half_angle: float
    blade_crank: float
    blade_link: float
    base_radius: float
    roller_arm: float
    rod_arm: float
    opening_angle: float
    required_mouth: float

    # ------------------------------------------------------------ blades
    @property
    def hinge_offset(self) -> float:
        """Distance ``e`` of each blade hinge from the duckbill axis."""
        return self.blade_length * np.sin(self.closed_half_angle)

    @property
    def hinge(self) -> np.ndarray:
        """Right blade hinge O1 in the planter frame."""
        return np.array([-self.L1 + self.hinge_offset,
                         -self.L2 + self.blade_length * np.cos(self.closed_half_angle)])

    def mouth_width(self, beta):
        """Width between the blade tips at opening ``beta`` (mm)."""
        d0 = self.closed_half_angle
        return 2.0 * self.blade_length * (np.sin(d0) - np.sin(d0 - np.asarray(beta, dtype=float)))

    @staticmethod
    def opening_for_mouth(width, blade_length, closed_half_angle):
        """The opening ``beta`` giving mouth ``width``, or NaN where no opening up to 45 deg does."""
        d0 = closed_half_angle
        sine = np.sin(d0) - np.asarray(width, dtype=float) / (2.0 * blade_length)
        with np.errstate(invalid="ignore"):
            beta = d0 - np.arcsin(sine)
        return np.where((np.abs(sine) <= 1.0) & (beta <= MAX_OPENING), beta, np.nan)

    def crank_pin(self, beta):
        """Right blade's crank pin J at opening ``beta``: (n, 2)."""
        beta = np.atleast_1d(np.asarray(beta, dtype=float))
        return self.hinge + self.blade_crank * np.stack([-np.cos(beta), -np.sin(beta)], axis=-1)

    def push_rod_end(self, beta):
        """Height of the push-rod end P2 on the axis at blade opening ``beta`` (mm)."""
        pin = self.crank_pin(beta)
        reach = pin[:, 0] + self.L1   # J's distance from the axis
        return pin[:, 1] + np.sqrt(self.blade_link**2 - reach**2)

    def blade_opening(self, drop):
        """Blade opening ``beta`` when P2 has moved ``drop`` mm down from its closed height.

        Closed form of the loop ``(e - c cos b)^2 + (k + c sin b)^2 = ell^2``,
        ``k`` the height of P2 above the hinge: ``c (k sin b - e cos b) =
        (ell^2 - e^2 - c^2 - k^2) / 2``, on the branch through ``b = 0``.
        """
        e, c, ell = self.hinge_offset, self.blade_crank, self.blade_link
        k = self.push_rod_end(0.0)[0] - self.hinge[1] - np.asarray(drop, dtype=float)
        rhs = (ell**2 - e**2 - c**2 - k**2) / (2.0 * c * np.hypot(e, k))
        return np.arctan2(e, k) + np.arcsin(np.clip(rhs, -1.0, 1.0))

    @property
    def stroke(self) -> float:
        """Push-rod travel from closed to fully open (mm)."""
        return float(self.push_rod_end(0.0)[0] - self.push_rod_end(self.opening_angle)[0])

    # ------------------------------------------------------------- lever
    @property
    def lever_pivot(self) -> np.ndarray:
        """H in the planter frame."""
        return np.array([-self.base_radius, -self.roller_arm])

    @property
    def lever_lift(self) -> float:
        """Lever angle that gives the full stroke (rad): the follower's lift."""
        return float(np.arcsin(self.stroke / self.rod_arm))

    def roller_centre(self, lam):
        """Roller centre I at lever angle ``lam`` and its first two derivatives in ``lam``: (n, 2) each."""
        lam = np.atleast_1d(np.asarray(lam, dtype=float))
        arm = self.roller_arm * np.stack([-np.sin(lam), np.cos(lam)], axis=-1)
        d_arm = self.roller_arm * np.stack([-np.cos(lam), -np.sin(lam)], axis=-1)
        return self.lever_pivot + arm, d_arm, -arm

    def rod_pin(self, lam):
        """Push-rod pin G at lever angle ``lam``: (n, 2)."""
        lam = np.atleast_1d(np.asarray(lam, dtype=float))
        return self.lever_pivot + self.rod_arm * np.stack([-np.cos(lam), -np.sin(lam)], axis=-1)

    def opening_of_lever(self, lam):
        """Blade opening ``beta`` (rad) at lever angle ``lam`` (the chain lever -> rod -> blades)."""
        return self.blade_opening(self.rod_arm * np.sin(np.asarray(lam, dtype=float)))

    # ------------------------------------------------------------ design
    @classmethod
    def design(cls, *, L1, L2, pot_diameter, mouth_clearance, blade_length, closed_half_angle,
               blade_crank, blade_link, base_radius, roller_arm, rod_arm=None,
               opening_angle=None, path="cam"):
        """Check the linkage and derive what the pot asks for.

        The mouth must be ``pot_diameter + 2 mouth_clearance`` wide. Without an
        explicit ``opening_angle`` (rad) the smallest opening giving that mouth is
        taken; an explicit one must give it. ``rod_arm`` defaults to the distance
        from the lever pivot to the duckbill axis, ``L1 - base_radius``.

        Raises
        ------
        DesignError
            Every geometric problem at once, each at its field (``cam.duckbill.*``,
            ``cam.lever.*``, ``cam.*`` under ``path``).
        """
        problems = []
        rod_arm = L1 - base_radius if rod_arm is None else rod_arm
        mouth = pot_diameter + 2.0 * mouth_clearance
        d0 = closed_half_angle
        if blade_length >= L2:
            problems.append(Problem(f"{path}.duckbill.blade_length", "blade_too_long",
                                    f"blades of {blade_length:g} mm do not fit below P1 "
                                    f"(L2 = {L2:g} mm)"))
        if rod_arm <= 0:
            problems.append(Problem(f"{path}.base_radius", "lever_does_not_fit",
                                    f"cam base radius {base_radius:g} mm leaves no lever arm "
                                    f"to the duckbill axis at L1 = {L1:g} mm"))
        widest = 2.0 * blade_length * (np.sin(d0) - np.sin(d0 - MAX_OPENING))
        if opening_angle is None:
            opening = float(cls.opening_for_mouth(mouth, blade_length, d0))
            if not np.isfinite(opening):
                problems.append(Problem(
                    f"{path}.pot_diameter", "mouth_narrower_than_pot",
                    f"a mouth of {mouth:g} mm (pot {pot_diameter:g} mm plus {mouth_clearance:g} mm "
                    f"each side) needs more than the largest opening, "
                    f"{np.degrees(MAX_OPENING):g} deg, of {blade_length:g}-mm blades gives "
                    f"({widest:.1f} mm): longer blades or a smaller pot"))
                opening = np.nan
        else:
            opening = float(opening_angle)
            if opening > MAX_OPENING:
                problems.append(Problem(f"{path}.opening_angle_deg", "opening_too_large",
                                        f"an opening of {np.degrees(opening):g} deg is more than "
                                        f"the blades may open ({np.degrees(MAX_OPENING):g} deg)"))
            width = 2.0 * blade_length * (np.sin(d0) - np.sin(d0 - opening))
            if width < mouth - 1e-9:
                problems.append(Problem(
                    f"{path}.opening_angle_deg", "mouth_narrower_than_pot",
                    f"an opening of {np.degrees(opening):g} deg gives a {width:.2f}-mm mouth, "
                    f"narrower than the {mouth:g} mm the pot asks for"))
        e = blade_length * np.sin(d0)
        if blade_crank >= e:
            problems.append(Problem(f"{path}.duckbill.blade_crank", "crank_crosses_axis",
                                    f"a {blade_crank:g}-mm blade crank reaches past the duckbill "
                                    f"axis (hinges {e:.2f} mm from it)"))
        elif np.isfinite(opening):
            reach = e - blade_crank * np.cos(np.linspace(0.0, opening, 64))
            if np.max(np.abs(reach)) >= blade_link:
                problems.append(Problem(f"{path}.duckbill.blade_link", "link_too_short",
                                        f"a {blade_link:g}-mm link cannot reach the push rod "
                                        f"({np.max(np.abs(reach)):.2f} mm from the crank pin)"))
        if problems:
            raise DesignError(problems)
        linkage = cls(L1=L1, L2=L2, blade_length=blade_length, closed_half_angle=d0,
                      blade_crank=blade_crank, blade_link=blade_link, base_radius=base_radius,
                      roller_arm=roller_arm, rod_arm=rod_arm, opening_angle=opening,
                      required_mouth=mouth)
        stroke = linkage.stroke
        if stroke >= rod_arm * np.sin(MAX_LEVER_ANGLE):
            problems.append(Problem(f"{path}.lever.rod_arm", "lever_angle_too_large",
                                    f"a {stroke:.2f}-mm push-rod stroke turns a {rod_arm:g}-mm lever "
                                    f"arm by more than {np.degrees(MAX_LEVER_ANGLE):g} deg"))
        top = linkage.push_rod_end(0.0)[0]
        if top >= -roller_arm:
            problems.append(Problem(f"{path}.lever.roller_arm", "push_rod_inverted",
                                    f"the push-rod end P2 ({top:.1f} mm) is not below the lever's "
                                    f"pin G ({-roller_arm:.1f} mm): shorten the roller arm or the "
                                    f"blades"))
        if problems:
            raise DesignError(problems)
        return linkage
