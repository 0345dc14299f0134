"""How a virtual campaign surveys a simulated rock: what marks the ground, how well
points are placed, where trees stand, what is assumed.

Every default is a stated field assumption (:meth:`CampaignDesign.describe` prints
them all); each is an option of ``fieldkit synth --survey``.

Scars
    An impact leaves a scar a geologist finds when the kinetic energy of the normal
    impact velocity, ``m vin^2 / 2``, reaches :data:`DEFAULT_SCAR_ENERGY_J` (5 kJ: a
    3,750 kg block arriving at 1.6 m/s normal to the ground; below that a boulder
    rolls or skips without a crater). Scars closer than
    :data:`DEFAULT_SCAR_SPACING_M` (2 m in plan) to the last one kept read as one scar
    (the first, uphill one is kept), and a scar behind the last one kept (the rock
    bounced back) is not told apart from it either. So several short bounces can be
    surveyed as one long "flight" -- as in the field.
Position error
    Each point's section ``x`` (plan, along the path) and ``z`` get normal errors of
    ``position_sigma_m`` and ``elevation_sigma_m`` (0.5 m each, the reduction's
    defaults: :mod:`fieldkit.reduce.uncertainty`). With ``correlation_length_m`` > 0
    the errors of successive points are correlated, ``rho = exp(-dx / L)`` (a
    receiver's multipath and satellite geometry drift slowly); under canopy
    (``canopy_x_m`` ranges) the SD is ``canopy_sigma_m`` instead.
Trees
    Trees stand along the path at random (a Poisson process of mean spacing
    ``tree_spacing_m``; none when it is 0). A flight passing a tree below
    ``tree_height_m`` scars its trunk at the height of the rock's centre above the
    ground there; the first tree of each surveyed flight is recorded (one strike fixes
    a parabola), its height measured with ``strike_height_sigma_m`` error and its
    distance from the launch scar taped (exact). The trees only mark the path: they
    slow the rock only when the model has ``tree_impacts`` switched on.
Launch angle
    Not observed. The reduction assumes ``theta0_deg`` (32.6 deg, the thesis's mean
    of the tree-defined flights at Tornado Mountain) wherever no tree defines a flight.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from fieldkit.errors import ArgumentError

#: Least normal-impact kinetic energy that leaves a scar [J] (module docstring).
DEFAULT_SCAR_ENERGY_J = 5_000.0
#: Scars closer than this in plan read as one [m].
DEFAULT_SCAR_SPACING_M = 2.0
#: Point-to-point position error in plan and in height [m] (the reduction's default).
DEFAULT_POSITION_SIGMA_M = 0.5
DEFAULT_ELEVATION_SIGMA_M = 0.5
#: Position error under canopy [m] (a handheld receiver under conifers).
DEFAULT_CANOPY_SIGMA_M = 2.0
#: Tree-strike height error [m] (the reduction's default).
DEFAULT_STRIKE_HEIGHT_SIGMA_M = 0.25
#: Highest strike a trunk records [m] (above it the rock passes over the crown).
DEFAULT_TREE_HEIGHT_M = 20.0
#: The launch angle the reduction assumes [deg] (thesis §2.2.2).
DEFAULT_THETA0_DEG = 32.6
#: Fewest scars (source included) that make a surveyed path (two flights).
MIN_SCARS = 3


@dataclass(frozen=True)
class CampaignDesign:
    """The survey of a virtual campaign (see the module docstring for each field)."""

    scar_energy_j: float = DEFAULT_SCAR_ENERGY_J
    scar_spacing_m: float = DEFAULT_SCAR_SPACING_M
    position_sigma_m: float = DEFAULT_POSITION_SIGMA_M
    elevation_sigma_m: float = DEFAULT_ELEVATION_SIGMA_M
    correlation_length_m: float = 0.0
    canopy_x_m: tuple[tuple[float, float], ...] = ()
    canopy_sigma_m: float = DEFAULT_CANOPY_SIGMA_M
    tree_spacing_m: float = 0.0
    tree_height_m: float = DEFAULT_TREE_HEIGHT_M
    strike_height_sigma_m: float = DEFAULT_STRIKE_HEIGHT_SIGMA_M
    theta0_deg: float = DEFAULT_THETA0_DEG
    max_scars: int | None = None
    min_scars: int = MIN_SCARS - 1

    def __post_init__(self) -> None:
        for name in (
            "scar_energy_j",
            "scar_spacing_m",
            "position_sigma_m",
            "elevation_sigma_m",
            "correlation_length_m",
            "canopy_sigma_m",
            "tree_spacing_m",
            "tree_height_m",
            "strike_height_sigma_m",
        ):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value)):
                raise ArgumentError(
                    f"must be a finite number (got {value!r})", source=name
                )
            if value < 0:
                raise ArgumentError(f"must be >= 0 (got {value:g})", source=name)
        for name in ("position_sigma_m", "elevation_sigma_m", "canopy_sigma_m",
                     "strike_height_sigma_m"):  # fmt: skip
            if getattr(self, name) > 100.0:
                raise ArgumentError(
                    f"must be <= 100 m (got {getattr(self, name):g}): a point known "
                    "no better than that does not locate a scar",
                    source=name,
                )
        if not (math.isfinite(self.theta0_deg) and 0.0 < self.theta0_deg < 90.0):
            raise ArgumentError(
                f"must be between 0 and 90 degrees (got {self.theta0_deg:g})",
                source="theta0_deg",
            )
        if self.max_scars is not None and not (
            isinstance(self.max_scars, int) and self.max_scars >= MIN_SCARS - 1
        ):
            raise ArgumentError(
                f"must be a whole number >= {MIN_SCARS - 1} (got {self.max_scars!r})",
                source="max_scars",
            )
        if not (isinstance(self.min_scars, int) and self.min_scars >= MIN_SCARS - 1):
            raise ArgumentError(
                f"must be a whole number >= {MIN_SCARS - 1} (got {self.min_scars!r})",
                source="min_scars",
            )
        for pair in self.canopy_x_m:
            if (
                len(pair) != 2
                or not all(math.isfinite(v) for v in pair)
                or (pair[0] >= pair[1])
            ):
                raise ArgumentError(
                    f"a canopy range is two chainages X0 < X1 (got {pair!r})",
                    source="canopy_x_m",
                )

    def sigma_at(self, x_m):
        """Plan/height position error SD at chainages ``x_m`` (canopy or open) [m]."""
        import numpy as np

        x = np.asarray(x_m, float)
        under = np.zeros(x.shape, bool)
        for x0, x1 in self.canopy_x_m:
            under |= (x >= x0) & (x <= x1)
        plan = np.where(under, self.canopy_sigma_m, self.position_sigma_m)
        height = np.where(under, self.canopy_sigma_m, self.elevation_sigma_m)
        return plan, height

    def describe(self) -> str:
        """Every survey assumption in one paragraph (the command's output, the JSON)."""
        parts = [
            f"scars where m vin^2/2 >= {self.scar_energy_j:g} J",
            f"scars closer than {self.scar_spacing_m:g} m merged (the uphill one kept)",
            f"position error {self.position_sigma_m:g} m in plan and "
            f"{self.elevation_sigma_m:g} m in height"
            + (
                f", correlated along the path over {self.correlation_length_m:g} m"
                if self.correlation_length_m > 0
                else ", independent from point to point"
            ),
        ]
        if self.canopy_x_m:
            ranges = ", ".join(f"{a:g}-{b:g} m" for a, b in self.canopy_x_m)
            parts.append(f"{self.canopy_sigma_m:g} m under canopy ({ranges})")
        if self.tree_spacing_m > 0:
            parts.append(
                f"trees every {self.tree_spacing_m:g} m on average (Poisson), strikes "
                f"below {self.tree_height_m:g} m recorded with "
                f"{self.strike_height_sigma_m:g} m height error"
            )
        else:
            parts.append("no trees")
        parts.append(
            f"launch angle not observed (reduced with theta0 {self.theta0_deg:g} deg)"
        )
        if self.max_scars is not None:
            parts.append(f"at most {self.max_scars} scars per path surveyed")
        if self.min_scars > MIN_SCARS - 1:
            parts.append(f"paths with fewer than {self.min_scars} scars not surveyed")
        return "; ".join(parts)

    def to_json(self) -> dict:
        """Plain dict (the campaign file)."""
        out = asdict(self)
        out["canopy_x_m"] = [list(p) for p in self.canopy_x_m]
        return out
