"""A rock hitting a protection fence, end to end (thesis chapter 8).

:func:`fence_impact` chains the chapter's steps for one impact:

1. the rebound off the net: measured (``speed_out_mps``, ``spin_out_radps``) or
   computed by impact mechanics in net axes from the contact radius and the impact
   angle to the net (:func:`fieldkit.physics.fences.fence_redirection`, eqs.
   4.20-4.24, worked example 8A);
2. with a rebound, the energy the net absorbs and its efficiency E_f/E_i
   (:func:`fieldkit.physics.fences.fence_energy_split`, eq. 8.1, worked example 8B);
3. for the impulse ``m v_i`` (or a given one), the contact time and peak force of each
   structure's time-force law (:mod:`fieldkit.physics.structure_forces`, eqs.
   8.2-8.7, section 8.3.2).

It returns numbers only (:class:`FenceImpact`); printing and files are the caller's.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from fieldkit.errors import ArgumentError
from fieldkit.physics.fences import (
    FenceEnergySplit,
    FenceRedirection,
    fence_energy_split,
    fence_redirection,
)
from fieldkit.physics.structure_forces import (
    THESIS_STRUCTURES,
    StructureLaw,
    contact_time,
    peak_force,
)

__all__ = ["FenceImpact", "StructureResponse", "fence_impact"]


@dataclass(frozen=True)
class StructureResponse:
    """How one structure absorbs the impulse (section 8.3.2).

    Attributes
    ----------
    law
        Its time-force law ``F = c t^x`` (eqs. 8.2-8.4).
    contact_time_s
        Time to absorb the impulse [s] (eqs. 8.5-8.7 inverted).
    peak_force_n
        Force at the end of the contact [N].
    """

    law: StructureLaw
    contact_time_s: float
    peak_force_n: float


@dataclass(frozen=True)
class FenceImpact:
    """Everything :func:`fence_impact` finds for one rock hitting a fence.

    Attributes
    ----------
    mass_kg, gyration_m
        The rock: m [kg] and k [m] (None when not known).
    speed_in_mps, spin_in_radps, angle_in_deg
        The impact: speed [m/s], spin [rad/s], angle to the net [deg] (None if not
        given).
    rebound
        ``"measured"``, ``"computed"`` or None (no rebound: no energy split).
    speed_out_mps, spin_out_radps, angle_out_deg
        The rebound (None without one; the angle also when not measured).
    redirection
        The impact-mechanics solution in net axes for a computed rebound, else None.
    e_n_from_angle_law
        The computed rebound used eq. 5.4 for e_N (no e_N given).
    split
        Energies before and after and what the fence absorbed [J], with a rebound.
    impulse_ns, impulse_given
        The impulse the structures absorb [N s]; False when it is ``m v_i``.
    structures
        One :class:`StructureResponse` per time-force law.
    """

    mass_kg: float
    gyration_m: float | None
    speed_in_mps: float
    spin_in_radps: float
    angle_in_deg: float | None
    rebound: str | None
    speed_out_mps: float | None
    spin_out_radps: float | None
    angle_out_deg: float | None
    redirection: FenceRedirection | None
    e_n_from_angle_law: bool
    split: FenceEnergySplit | None
    impulse_ns: float
    impulse_given: bool
    structures: tuple[StructureResponse, ...]


def _require(ok: bool, name: str, message: str) -> None:
    if not ok:
        raise ArgumentError(message, source=name)


def fence_impact(
    mass_kg: float,
    speed_in_mps: float,
    *,
    gyration_m: float | None = None,
    spin_in_radps: float = 0.0,
    radius_m: float | None = None,
    angle_in_deg: float | None = None,
    speed_out_mps: float | None = None,
    spin_out_radps: float | None = None,
    angle_out_deg: float | None = None,
    e_n: float | None = None,
    friction: float = math.inf,
    impulse_ns: float | None = None,
    structures: Iterable[StructureLaw] = THESIS_STRUCTURES.values(),
) -> FenceImpact:
    """Rebound, energy split and structure forces of one rock hitting a fence.

    The rebound is measured when ``speed_out_mps`` is given; otherwise it is computed
    when ``radius_m`` or ``angle_in_deg`` is given (both are then needed, with
    ``gyration_m``); otherwise there is none, and only the structure forces follow.

    Parameters
    ----------
    mass_kg
        Rock mass m [kg], > 0.
    speed_in_mps
        Impact speed v_i [m/s], > 0.
    gyration_m
        Radius of gyration k [m]; needed for any rebound (rotational energy).
    spin_in_radps
        Spin at impact [rad/s], positive when it moves the contact point down the net
        (thesis Fig. 8.3).
    radius_m
        Contact radius r [m], for a computed rebound.
    angle_in_deg
        Impact angle to the net theta_i [deg], in (0, 90], for a computed rebound.
    speed_out_mps, spin_out_radps, angle_out_deg
        Measured rebound: speed [m/s] (>= 0), spin [rad/s] (default 0) and angle to
        the net [deg] (reported only).
    e_n, friction
        Normal restitution (>= 0; default eq. 5.4) and friction (>= 0; default inf,
        slip stops) at the net, for a computed rebound.
    impulse_ns
        Impulse the structures absorb [N s], > 0 (default ``m v_i``).
    structures
        Time-force laws to compare (default: the rigid, flexible and stiff
        structures of section 8.3.2).

    Returns
    -------
    FenceImpact

    Raises
    ------
    ArgumentError
        Naming the argument at fault, e.g. ``source="angle_in_deg"`` for a computed
        rebound without the impact angle.

    Examples
    --------
    Worked example 8B: the net absorbs 97.4 kJ (72 %); 11,440 N s stop the rock in
    0.15 s against a rigid wall.

    >>> f = fence_impact(520.0, 22.0, gyration_m=0.35, spin_in_radps=18.0,
    ...                  speed_out_mps=11.5, spin_out_radps=-11.6)
    >>> round(float(f.split.absorbed_j) / 1e3, 1), f.rebound
    (97.5, 'measured')
    >>> round(f.structures[0].contact_time_s, 2)
    0.15
    """
    _require(
        math.isfinite(speed_in_mps) and speed_in_mps > 0,
        "speed_in_mps",
        f"must be positive, got {speed_in_mps:g}",
    )
    if impulse_ns is not None:
        _require(impulse_ns > 0, "impulse_ns", f"must be positive, got {impulse_ns:g}")
    for name, value in (
        ("spin_out_radps", spin_out_radps),
        ("angle_out_deg", angle_out_deg),
    ):
        if value is not None and speed_out_mps is None:
            raise ArgumentError(
                "a measured rebound needs `speed_out_mps` too", source=name
            )
    redirection = None
    rebound = None
    speed_out = spin_out = angle_out = None
    if speed_out_mps is not None:
        _require(
            speed_out_mps >= 0,
            "speed_out_mps",
            f"must not be negative, got {speed_out_mps:g}",
        )
        rebound = "measured"
        speed_out = speed_out_mps
        spin_out = 0.0 if spin_out_radps is None else spin_out_radps
        angle_out = angle_out_deg
    elif radius_m is not None or angle_in_deg is not None:
        redirection = _computed_rebound(
            speed_in_mps, angle_in_deg, spin_in_radps, radius_m, gyration_m, e_n,
            friction,
        )  # fmt: skip
        rebound = "computed"
        speed_out = float(redirection.speed_out_mps)
        spin_out = float(redirection.omega_f_radps)
        angle_out = float(redirection.angle_out_deg)
    split = None
    if rebound is not None:
        if gyration_m is None:
            raise ArgumentError(
                "the energy split needs `gyration_m` or `inertia_kgm2`",
                source="gyration_m",
            )
        split = fence_energy_split(
            mass_kg, gyration_m, speed_in_mps, spin_in_radps, speed_out, spin_out
        )
    p = mass_kg * speed_in_mps if impulse_ns is None else impulse_ns
    responses = tuple(
        StructureResponse(law, float(contact_time(law, p)), float(peak_force(law, p)))
        for law in structures
    )
    return FenceImpact(
        mass_kg=mass_kg,
        gyration_m=gyration_m,
        speed_in_mps=speed_in_mps,
        spin_in_radps=spin_in_radps,
        angle_in_deg=angle_in_deg,
        rebound=rebound,
        speed_out_mps=speed_out,
        spin_out_radps=spin_out,
        angle_out_deg=angle_out,
        redirection=redirection,
        e_n_from_angle_law=redirection is not None and e_n is None,
        split=split,
        impulse_ns=p,
        impulse_given=impulse_ns is not None,
        structures=responses,
    )


def _computed_rebound(
    speed_in_mps: float,
    angle_in_deg: float | None,
    spin_in_radps: float,
    radius_m: float | None,
    gyration_m: float | None,
    e_n: float | None,
    friction: float,
) -> FenceRedirection:
    """The rebound by impact mechanics, after checking it has what it needs."""
    if radius_m is None:
        raise ArgumentError(
            "the computed rebound needs the contact radius", source="radius_m"
        )
    if angle_in_deg is None:
        raise ArgumentError(
            "the computed rebound needs the impact angle to the net",
            source="angle_in_deg",
        )
    if gyration_m is None:
        raise ArgumentError(
            "the computed rebound needs `gyration_m` or `inertia_kgm2`",
            source="gyration_m",
        )
    _require(radius_m > 0, "radius_m", f"must be positive, got {radius_m:g}")
    _require(
        0 < angle_in_deg <= 90,
        "angle_in_deg",
        f"must be in (0, 90] deg, got {angle_in_deg:g}",
    )
    if e_n is not None:
        _require(e_n >= 0, "e_n", f"must not be negative, got {e_n:g}")
    _require(friction >= 0, "friction", f"must not be negative, got {friction:g}")
    return fence_redirection(
        speed_in_mps,
        angle_in_deg,
        spin_in_radps,
        radius_m=radius_m,
        gyration_m=gyration_m,
        e_n=e_n,
        friction=friction,
    )
