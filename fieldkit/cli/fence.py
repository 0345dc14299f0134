"""`fieldkit fence`: a rock hitting a protection fence (thesis chapter 8).

Energy the net absorbs from an oblique impact (worked examples 8A/8B, eq. 8.1) and the
time-force comparison of rigid, flexible and stiff structures (section 8.3.2).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated

import typer

from fieldkit.cli.common import GyrationOpt, MassOpt, RadiusOpt, one_line_errors
from fieldkit.errors import ArgumentError

_LAW_HELP = "as COEFFICIENT,EXPONENT for F = c t^x (N, s)"
_SLIP_STOPS = "slip stops (rolls off the net)"


@one_line_errors
def fence(
    mass: MassOpt = None,
    gyration: GyrationOpt = None,
    inertia: Annotated[
        float | None,
        typer.Option(
            "--inertia", help="Moment of inertia I (kg m^2), instead of --gyration."
        ),
    ] = None,
    radius: RadiusOpt = None,
    speed_in: Annotated[
        float | None, typer.Option("--speed-in", help="Impact speed v_i (m/s).")
    ] = None,
    angle_in: Annotated[
        float | None,
        typer.Option(
            "--angle-in",
            help="Impact angle theta_i between the velocity and the net "
            "(deg), 90 = normal impact.",
        ),
    ] = None,
    spin_in: Annotated[
        float,
        typer.Option(
            "--spin-in",
            help="Spin at impact omega_i (rad/s); positive when it moves the "
            "contact point down the net (thesis Fig. 8.3).",
        ),
    ] = 0.0,
    speed_out: Annotated[
        float | None,
        typer.Option(
            "--speed-out",
            help="Measured speed leaving the net v_f (m/s). Omit it (and "
            "give --radius, --angle-in) to compute the rebound by impact mechanics.",
        ),
    ] = None,
    angle_out: Annotated[
        float | None,
        typer.Option(
            "--angle-out",
            help="Measured angle leaving the net theta_f (deg) (reported only).",
        ),
    ] = None,
    spin_out: Annotated[
        float | None,
        typer.Option(
            "--spin-out",
            help="Measured spin leaving the net omega_f (rad/s) "
            "(default 0 with --speed-out).",
        ),
    ] = None,
    e_n: Annotated[
        float | None,
        typer.Option(
            "--e-n",
            help="Normal coefficient of restitution at the net for the computed "
            "rebound (default: eq. 5.4, 19.5 theta_i^-1.03).",
        ),
    ] = None,
    friction: Annotated[
        float,
        typer.Option(
            "--friction",
            help="Friction coefficient at the net for the computed rebound "
            "(default inf: slip stops, eqs. 4.20-4.22).",
        ),
    ] = math.inf,
    impulse: Annotated[
        float | None,
        typer.Option(
            "--impulse",
            help="Impulse the structures must absorb (N s) (default m v_i).",
        ),
    ] = None,
    rigid: Annotated[
        str, typer.Option("--rigid", help=f"Rigid wall law {_LAW_HELP} (eq. 8.2).")
    ] = "1e6,1",
    flexible: Annotated[
        str,
        typer.Option("--flexible", help=f"Flexible fence law {_LAW_HELP} (eq. 8.3)."),
    ] = "4e4,2",
    stiff: Annotated[
        str, typer.Option("--stiff", help=f"Stiff fence law {_LAW_HELP} (eq. 8.4).")
    ] = "3e4,0.6",
    figure: Annotated[
        Path | None,
        typer.Option(
            "--figure",
            help="PNG: energy split and time-impulse / time-force curves "
            "(Figs. 8.6-8.8).",
        ),
    ] = None,
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="Write the results as JSON.")
    ] = None,
) -> None:
    """Energy a fence absorbs from an oblique rock impact, and structure forces.

    The rock's energy 1/2 m v^2 + 1/2 I omega^2 before and after the net gives
    the energy absorbed and the efficiency E_f/E_i (eq. 8.1). The rebound is
    either measured (--speed-out, --spin-out) or computed by impact mechanics
    from --radius and --angle-in (eqs. 4.20-4.24 in axes along the net, worked
    example 8A). For the impulse m v_i, the rigid, flexible and stiff
    time-force laws (eqs. 8.2-8.7) give the contact time and peak force.

    Example (thesis worked example 8B: the net absorbs 97.4 kJ, 72 %):

        fieldkit fence --mass 520 --gyration 0.35 --speed-in 22 --spin-in 18
        --speed-out 11.5 --spin-out=-11.6 --figure fence.png

    Computed rebound (worked example 8A inputs, e_N by eq. 5.4):

        fieldkit fence --mass 520 --gyration 0.35 --radius 0.43 --speed-in 22
        --angle-in 50 --spin-in 18
    """
    from fieldkit.outputs import write_text_atomic
    from fieldkit.physics.fences import fence_energy_split, fence_redirection
    from fieldkit.physics.structure_forces import StructureLaw, contact_time, peak_force

    if mass is None:
        raise ArgumentError("the rock's mass is required", source="--mass")
    if speed_in is None:
        raise ArgumentError("the impact speed is required", source="--speed-in")
    _require(mass > 0, "--mass", f"must be positive, got {mass:g}")
    _require(speed_in > 0, "--speed-in", f"must be positive, got {speed_in:g}")
    k = _gyration(mass, gyration, inertia)
    laws = [
        _law("rigid", rigid, "--rigid", StructureLaw),
        _law("flexible", flexible, "--flexible", StructureLaw),
        _law("stiff", stiff, "--stiff", StructureLaw),
    ]
    if impulse is not None:
        _require(impulse > 0, "--impulse", f"must be positive, got {impulse:g}")
    p = mass * speed_in if impulse is None else impulse
    if figure is not None and figure.suffix.lower() != ".png":
        raise ArgumentError("the figure must be a .png file", source="--figure")

    results: dict[str, object] = {
        "mass_kg": mass,
        "gyration_m": k,
        "speed_in_mps": speed_in,
        "spin_in_radps": spin_in,
    }
    lines = [
        f"rock: m = {mass:g} kg, k = {_fmt(k)} m, I = m k^2 = "
        f"{_fmt(mass * k * k if k is not None else None)} kg m^2"
    ]
    rebound = None
    for option, value in (("--spin-out", spin_out), ("--angle-out", angle_out)):
        if value is not None and speed_out is None:
            raise ArgumentError(
                "a measured rebound needs --speed-out too", source=option
            )
    if figure is not None and out is not None and figure.resolve() == out.resolve():
        raise ArgumentError(
            "--figure and --out must be different files", source="--out"
        )
    if speed_out is not None:
        _require(
            speed_out >= 0, "--speed-out", f"must not be negative, got {speed_out:g}"
        )
        rebound = (
            speed_out,
            0.0 if spin_out is None else spin_out,
            angle_out,
            "measured",
        )
    elif radius is not None or angle_in is not None:
        if radius is None:
            raise ArgumentError(
                "the computed rebound needs the contact radius", source="--radius"
            )
        if angle_in is None:
            raise ArgumentError(
                "the computed rebound needs the impact angle to the net",
                source="--angle-in",
            )
        if k is None:
            raise ArgumentError(
                "the computed rebound needs --gyration or --inertia",
                source="--gyration",
            )
        _require(radius > 0, "--radius", f"must be positive, got {radius:g}")
        _require(
            0 < angle_in <= 90,
            "--angle-in",
            f"must be in (0, 90] deg, got {angle_in:g}",
        )
        if e_n is not None:
            _require(e_n >= 0, "--e-n", f"must not be negative, got {e_n:g}")
        _require(friction >= 0, "--friction", f"must not be negative, got {friction:g}")
        red = fence_redirection(
            speed_in,
            angle_in,
            spin_in,
            radius_m=radius,
            gyration_m=k,
            e_n=e_n,
            friction=friction,
        )
        rebound = (
            float(red.speed_out_mps),
            float(red.omega_f_radps),
            float(red.angle_out_deg),
            "computed",
        )
        results["redirection"] = {
            "v_it_mps": float(red.v_it_mps),
            "v_in_mps": float(red.v_in_mps),
            "e_n": float(red.e_n),
            "v_ft_mps": float(red.v_ft_mps),
            "v_fn_mps": float(red.v_fn_mps),
            "slip_stops": bool(red.slip_stops),
        }
        lines += [
            f"impact (net axes): v_iT = {float(red.v_it_mps):.2f}, "
            f"v_iN = {float(red.v_in_mps):.2f} m/s, theta_i = {angle_in:g} deg, "
            f"omega_i = {spin_in:g} rad/s",
            f"rebound by impact mechanics (eqs. 4.20-4.24): e_N = {float(red.e_n):.3f}"
            f"{' (eq. 5.4)' if e_n is None else ''}, v_fT = {float(red.v_ft_mps):.2f}, "
            f"v_fN = {float(red.v_fn_mps):.2f} m/s, omega_f = "
            f"{float(red.omega_f_radps):.2f} rad/s, "
            f"{_SLIP_STOPS if red.slip_stops else 'slips throughout'}",
        ]
    if rebound is not None:
        if k is None:
            raise ArgumentError(
                "the energy split needs --gyration or --inertia", source="--gyration"
            )
        v_f, w_f, a_f, how = rebound
        split = fence_energy_split(mass, k, speed_in, spin_in, v_f, w_f)
        results["energy"] = {name: float(v) for name, v in split._asdict().items()}
        results["speed_out_mps"], results["spin_out_radps"] = v_f, w_f
        angle_text = "" if a_f is None else f", theta_f = {a_f:.1f} deg"
        lines += [
            f"impact:      v_i = {speed_in:.2f} m/s, omega_i = {spin_in:.2f} rad/s"
            + ("" if angle_in is None else f", theta_i = {angle_in:g} deg"),
            f"restitution: v_f = {v_f:.2f} m/s, omega_f = {w_f:.2f} rad/s{angle_text}"
            f" ({how})",
            "energy [kJ]      kinetic  rotational     total",
            f"  impact      {split.kinetic_in_j / 1e3:10.2f} "
            f"{split.rotational_in_j / 1e3:11.2f} {split.total_in_j / 1e3:9.2f}",
            f"  restitution {split.kinetic_out_j / 1e3:10.2f} "
            f"{split.rotational_out_j / 1e3:11.2f} {split.total_out_j / 1e3:9.2f}",
            f"absorbed by the fence: {split.absorbed_j / 1e3:.2f} kJ "
            f"({split.absorbed_fraction:.1%} of the impact energy)",
            f"energy efficiency E_f/E_i (eq. 8.1): {split.efficiency:.1%}",
        ]
    else:
        split = None
        lines.append(
            "no rebound given: add --speed-out (measured) or --radius and "
            "--angle-in (computed) for the energy split"
        )

    source = "m v_i" if impulse is None else "--impulse"
    lines += [
        f"time-force for impulse p = {p:,.0f} N s ({source}; section 8.3.2)",
        "  structure  law                 contact time [s]  peak force [kN]",
    ]
    results["impulse_ns"] = p
    results["structures"] = []
    for law in laws:
        t_end, f_max = float(contact_time(law, p)), float(peak_force(law, p))
        results["structures"].append(
            {
                "name": law.name,
                "coefficient": law.coefficient,
                "exponent": law.exponent,
                "contact_time_s": t_end,
                "peak_force_n": f_max,
            }
        )
        text = f"F = {law.coefficient:g} t^{law.exponent:g}"
        lines.append(f"  {law.name:<10} {text:<20} {t_end:16.3f} {f_max / 1e3:16.1f}")

    if figure is not None:
        from fieldkit.viz.fence_figure import write_fence_figure

        write_fence_figure(figure, p, laws, split)
        lines.append(f"figure: {figure}")
    if out is not None:
        write_text_atomic(out, json.dumps(results, indent=2) + "\n")
        lines.append(f"results: {out}")
    typer.echo("\n".join(lines))


def _require(ok: bool, option: str, message: str) -> None:
    if not ok:
        raise ArgumentError(message, source=option)


def _fmt(value: float | None) -> str:
    return "?" if value is None else f"{value:.4g}"


def _gyration(
    mass: float, gyration: float | None, inertia: float | None
) -> float | None:
    if gyration is not None and inertia is not None:
        raise ArgumentError(
            "give --gyration or --inertia, not both", source="--inertia"
        )
    if gyration is not None:
        _require(gyration >= 0, "--gyration", f"must not be negative, got {gyration:g}")
        return gyration
    if inertia is not None:
        _require(inertia >= 0, "--inertia", f"must not be negative, got {inertia:g}")
        return math.sqrt(inertia / mass)
    return None


def _law(name: str, text: str, option: str, law_class: type) -> object:
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        coefficient, exponent = (float(part) for part in parts)
    except ValueError:
        raise ArgumentError(
            f"expected COEFFICIENT,EXPONENT (e.g. 3e4,0.6), got {text!r}", source=option
        ) from None
    if not (
        coefficient > 0
        and exponent > 0
        and math.isfinite(coefficient)
        and math.isfinite(exponent)
    ):
        raise ArgumentError(
            f"coefficient and exponent must be positive, got {text!r}", source=option
        )
    return law_class(name, coefficient, exponent)
