"""`fieldkit fence`: a rock hitting a protection fence (thesis chapter 8).

Energy the net absorbs from an oblique impact (worked examples 8A/8B, eq. 8.1) and the
time-force comparison of rigid, flexible and stiff structures (section 8.3.2).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import (
    DimensionsOpt,
    GyrationOpt,
    InertiaOpt,
    MassOpt,
    RadiusOpt,
    ShapeOpt,
    UnitWeightOpt,
    body_from_options,
    check_physical,
    one_line_errors,
    print_body_notes,
)
from fieldkit.cli.progress import report_written
from fieldkit.errors import ArgumentError
from fieldkit.physics.fence_impact import FenceImpact
from fieldkit.physics.restitution import angle_dependent_restitution
from fieldkit.physics.structure_forces import StructureLaw

#: Body values `fence` always needs (a rebound also needs k, a computed one also r).
BODY_NEEDS = ("mass_kg",)

#: Where `fence`'s flags differ from :data:`fieldkit.cli.common.FLAGS`.
_FLAGS = {"e_n": "--e-n"}

_LAW_HELP = "as COEFFICIENT,EXPONENT for F = c t^x (N, s)"
_SLIP_STOPS = "slip stops (rolls off the net)"


@one_line_errors(flags=_FLAGS)
def fence(
    mass: MassOpt = None,
    gyration: GyrationOpt = None,
    inertia: InertiaOpt = None,
    radius: RadiusOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
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
    example 8A). A rebound with more energy than the impact is refused: a
    fence is passive, E_f/E_i is at most 1 (a computed one gains energy only
    with e_N above 1, given or from eq. 5.4 at a shallow --angle-in). For the
    impulse m v_i, the rigid, flexible and stiff time-force laws (eqs.
    8.2-8.7) give the contact time and peak force.

    Example (thesis worked example 8B: the net absorbs 97.5 kJ, 72 %; the
    thesis prints 97.4, subtracting rounded totals):

        fieldkit fence --mass 520 --gyration 0.35 --speed-in 22 \\
          --spin-in 18 --speed-out 11.5 --spin-out=-11.6 \\
          --figure out/fence.png

    Computed rebound (worked example 8A inputs, e_N by eq. 5.4):

        fieldkit fence --mass 520 --gyration 0.35 --radius 0.43 \\
          --speed-in 22 --angle-in 50 --spin-in 18
    """
    from fieldkit.outputs import OutputSet, write_json
    from fieldkit.physics.fence_impact import fence_impact

    rock = body_from_options(
        mass, radius, gyration, shape, dimensions, unit_weight, inertia
    ).require(*BODY_NEEDS, source="fieldkit fence")
    if speed_in is None:
        raise ArgumentError("the impact speed is required", source="--speed-in")
    for value, flag, quantity in (
        (speed_in, "--speed-in", "speed_mps"),
        (speed_out, "--speed-out", "speed_mps"),
        (spin_in, "--spin-in", "spin_radps"),
        (spin_out, "--spin-out", "spin_radps"),
        (e_n, "--e-n", "e_n"),
        (friction, "--friction", "friction"),
        (angle_in, "--angle-in", "angle_deg"),
        (angle_out, "--angle-out", "angle_deg"),
        (impulse, "--impulse", "impulse_ns"),
    ):
        check_physical(value, flag, quantity)
    laws = [
        _law("rigid", rigid, "--rigid"),
        _law("flexible", flexible, "--flexible"),
        _law("stiff", stiff, "--stiff"),
    ]
    if figure is not None and figure.suffix.lower() != ".png":
        raise ArgumentError("the figure must be a .png file", source="--figure")
    outputs = OutputSet()
    for path, flag in ((figure, "--figure"), (out, "--out")):
        if path is not None:
            outputs.plan(path, argument=flag)
    # a typed --radius or an --angle-in asks for the computed rebound; a shape's
    # radius alone does not
    computed = radius is not None or angle_in is not None
    if computed and e_n is None and angle_in is not None and 0 < angle_in <= 90:
        with np.errstate(over="ignore", divide="ignore"):
            law = float(angle_dependent_restitution(angle_in))
        check_physical(law, f"e_N by eq. 5.4 at --angle-in {angle_in:g} deg", "e_n")
    result = fence_impact(
        rock.mass_kg,
        speed_in,
        gyration_m=rock.gyration_m,
        spin_in_radps=spin_in,
        radius_m=rock.radius_m if computed else None,
        angle_in_deg=angle_in,
        speed_out_mps=speed_out,
        spin_out_radps=spin_out,
        angle_out_deg=angle_out,
        e_n=e_n,
        friction=friction,
        impulse_ns=impulse,
        structures=laws,
    )
    lines = _report(result)
    if figure is not None:
        from fieldkit.viz.fence_figure import write_fence_figure

        write_fence_figure(
            figure, result.impulse_ns, laws, result.split, outputs=outputs
        )
    if out is not None:
        write_json(out, _results(result), outputs)
    written = outputs.commit()
    typer.echo("\n".join(lines))
    print_body_notes(rock)
    report_written(written)


def _report(f: FenceImpact) -> list[str]:
    """The printed lines: the rock, the rebound and energy split, the structures."""
    k = f.gyration_m
    lines = [
        f"rock: m = {f.mass_kg:g} kg, k = {_fmt(k)} m, I = m k^2 = "
        f"{_fmt(f.mass_kg * k * k if k is not None else None)} kg m^2"
    ]
    red = f.redirection
    if red is not None:
        lines += [
            f"impact (net axes): v_iT = {float(red.v_it_mps):.2f}, "
            f"v_iN = {float(red.v_in_mps):.2f} m/s, theta_i = {f.angle_in_deg:g} deg, "
            f"omega_i = {f.spin_in_radps:g} rad/s",
            f"rebound by impact mechanics (eqs. 4.20-4.24): e_N = {float(red.e_n):.3f}"
            f"{' (eq. 5.4)' if f.e_n_from_angle_law else ''}, "
            f"v_fT = {float(red.v_ft_mps):.2f}, "
            f"v_fN = {float(red.v_fn_mps):.2f} m/s, omega_f = "
            f"{float(red.omega_f_radps):.2f} rad/s, "
            f"{_SLIP_STOPS if red.slip_stops else 'slips throughout'}",
        ]
    split = f.split
    if split is not None:
        angle_text = (
            ""
            if f.angle_out_deg is None
            else (f", theta_f = {f.angle_out_deg:.1f} deg")
        )
        lines += [
            f"impact:      v_i = {f.speed_in_mps:.2f} m/s, "
            f"omega_i = {f.spin_in_radps:.2f} rad/s"
            + ("" if f.angle_in_deg is None else f", theta_i = {f.angle_in_deg:g} deg"),
            f"restitution: v_f = {f.speed_out_mps:.2f} m/s, "
            f"omega_f = {f.spin_out_radps:.2f} rad/s{angle_text} ({f.rebound})",
            "energy [kJ]      kinetic  rotational     total",
            f"  impact      {split.kinetic_in_j / 1e3:10.2f} "
            f"{split.rotational_in_j / 1e3:11.2f} {split.total_in_j / 1e3:9.2f}",
            f"  restitution {split.kinetic_out_j / 1e3:10.2f} "
            f"{split.rotational_out_j / 1e3:11.2f} {split.total_out_j / 1e3:9.2f}",
            f"absorbed by the fence: {split.absorbed_j / 1e3:.2f} kJ "
            f"({split.absorbed_fraction:.1%} of the impact energy)",
            f"energy efficiency E_f/E_i (eq. 8.1): {split.efficiency:.1%}",
        ]  # fmt: skip
    else:
        lines.append(
            "no rebound given: add --speed-out (measured) or --radius and "
            "--angle-in (computed) for the energy split"
        )
    source = "--impulse" if f.impulse_given else "m v_i"
    lines += [
        f"time-force for impulse p = {f.impulse_ns:,.0f} N s ({source}; section 8.3.2)",
        "  structure  law                 contact time [s]  peak force [kN]",
    ]
    for s in f.structures:
        law = s.law
        text = f"F = {law.coefficient:g} t^{law.exponent:g}"
        lines.append(
            f"  {law.name:<10} {text:<20} {s.contact_time_s:16.3f} "
            f"{s.peak_force_n / 1e3:16.1f}"
        )
    return lines


def _results(f: FenceImpact) -> dict[str, object]:
    """The JSON written by ``-o``."""
    results: dict[str, object] = {
        "mass_kg": f.mass_kg,
        "gyration_m": f.gyration_m,
        "speed_in_mps": f.speed_in_mps,
        "spin_in_radps": f.spin_in_radps,
    }
    red = f.redirection
    if red is not None:
        results["redirection"] = {
            "v_it_mps": float(red.v_it_mps),
            "v_in_mps": float(red.v_in_mps),
            "e_n": float(red.e_n),
            "v_ft_mps": float(red.v_ft_mps),
            "v_fn_mps": float(red.v_fn_mps),
            "slip_stops": bool(red.slip_stops),
        }
    if f.split is not None:
        results["energy"] = {name: float(v) for name, v in f.split._asdict().items()}
        results["speed_out_mps"] = f.speed_out_mps
        results["spin_out_radps"] = f.spin_out_radps
    results["impulse_ns"] = f.impulse_ns
    results["structures"] = [
        {
            "name": s.law.name,
            "coefficient": s.law.coefficient,
            "exponent": s.law.exponent,
            "contact_time_s": s.contact_time_s,
            "peak_force_n": s.peak_force_n,
        }
        for s in f.structures
    ]
    return results


def _fmt(value: float | None) -> str:
    return "?" if value is None else f"{value:.4g}"


def _law(name: str, text: str, option: str) -> StructureLaw:
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
    if not (1.0 <= coefficient <= 1e12 and exponent <= 10.0):
        raise ArgumentError(
            f"coefficient must be in [1, 1e12] N/s^x and exponent at most 10, got "
            f"{text!r} (the thesis laws are 1e6,1; 4e4,2 and 3e4,0.6: beyond these "
            "bounds a contact lasts beyond any impact or no time at all)",
            source=option,
        )
    return StructureLaw(name, coefficient, exponent)
