"""`fieldkit impact`: the impact calculator of thesis ch. 4 (rough, rotating body)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from fieldkit.cli.common import (
    DimensionsOpt,
    GyrationOpt,
    MassOpt,
    RadiusOpt,
    ShapeOpt,
    UnitWeightOpt,
    body_from_options,
    check_physical,
    one_line_errors,
    print_body_notes,
    warn,
)
from fieldkit.cli.progress import report_written
from fieldkit.errors import ArgumentError
from fieldkit.outputs import OutputSet, write_json
from fieldkit.physics.bodies import ResolvedBody
from fieldkit.physics.impact_mechanics import (
    ImpactResult,
    minimum_friction_to_stop_slip,
    rough_body_impact,
)
from fieldkit.physics.impulse_history import impulse_history
from fieldkit.physics.restitution import (
    ANGLE_LAW_A,
    ANGLE_LAW_B,
    VELOCITY_SCALE_MPS,
    angle_dependent_restitution,
    constant_restitution,
    velocity_scaled_restitution,
)

#: Body values `impact` needs (the mass is optional: it only scales the energies).
BODY_NEEDS = ("radius_m", "gyration_m")

#: Where `impact`'s flags differ from :data:`fieldkit.cli.common.FLAGS`.
_FLAGS = {
    "theta_i_deg": "the impact angle (--angle, or atan(-vn/vt))",
    "a": "--a",
    "b": "--b",
}


def _positive(option: str, value: float) -> None:
    if not (math.isfinite(value) and value > 0):
        raise ArgumentError(f"{option} must be > 0 (got {value:g})")


def _impact_velocity(
    speed: float | None, angle: float | None, vt: float | None, vn: float | None
) -> tuple[float, float]:
    """(v_iT, v_iN) from --speed/--angle or --vt/--vn."""
    polar = speed is not None or angle is not None
    parts = vt is not None or vn is not None
    if polar and parts:
        raise ArgumentError("give --speed and --angle, or --vt and --vn, not both")
    if polar:
        if speed is None or angle is None:
            raise ArgumentError("--speed and --angle go together (give both)")
        _positive("--speed", speed)
        check_physical(speed, "--speed", "speed_mps")
        if not (math.isfinite(angle) and 0.0 < angle < 180.0):
            raise ArgumentError(
                f"--angle must be between 0 and 180 deg, exclusive (got {angle:g})"
            )
        theta = math.radians(angle)
        return speed * math.cos(theta), -speed * math.sin(theta)
    if vt is None or vn is None:
        raise ArgumentError(
            "give the impact velocity: --speed and --angle, or --vt and --vn"
        )
    if not math.isfinite(vt):
        raise ArgumentError(f"--vt must be finite (got {vt:g})")
    if not (math.isfinite(vn) and vn < 0):
        raise ArgumentError(
            f"--vn must be < 0, i.e. moving into the ground (got {vn:g})"
        )
    check_physical(vt, "--vt", "speed_mps")
    check_physical(vn, "--vn", "speed_mps")
    return vt, vn


#: --law choices: constant e_N (--en), eq. 5.4 (angle), eq. 7.1 (velocity).
_LAWS = ("constant", "angle", "velocity")


def _restitution(
    law: str | None,
    en: float | None,
    a: float,
    b: float,
    scale: float,
    theta_i_deg: float,
    v_in: float,
) -> tuple[float, str]:
    """The e_N to use and a one-line description of where it came from."""
    if law is None:
        law = "constant" if en is not None else None
    if law is None:
        raise ArgumentError(
            "give --en E (constant e_N) or a restitution law, e.g. --law angle"
        )
    if law not in _LAWS:
        raise ArgumentError(f"--law must be one of {', '.join(_LAWS)} (got {law!r})")
    if law == "angle":
        if en is not None:
            raise ArgumentError("--en is not used with --law angle (it gives e_N)")
        e = float(angle_dependent_restitution(theta_i_deg, a, b))
        return e, f"eq. 5.4, {a:g} x {theta_i_deg:.1f}^-{b:g}"
    if en is None:
        raise ArgumentError(f"--law {law} needs --en")
    if law == "velocity":
        e = float(velocity_scaled_restitution(v_in, en, scale))
        return e, f"eq. 7.1, {en:g} / (1 + ({v_in:.2f}/{scale:g})^2)"
    e = float(constant_restitution(en))
    return e, "constant"


def _number(value: object) -> float | bool | None:
    value = np.asarray(value).item()
    if isinstance(value, bool):
        return value
    return None if not math.isfinite(value) else float(value)


def _report(
    res: ImpactResult,
    body: ResolvedBody,
    v_it: float,
    v_in: float,
    spin: float,
    e_n: float,
    e_source: str,
    friction: float,
    offset: float,
    mu_min: float | None,
) -> str:
    """The printed table."""
    f = {k: float(np.asarray(v)) for k, v in vars(res).items()}
    mass_known = body.mass_kg is not None
    shape = f"{body.shape} " if body.shape else ""
    lines = [
        "fieldkit impact: rough rotating body on the slope (thesis ch. 4, App. C)",
        f"body     {shape}r = {body.radius_m:.3f} m, k = {body.gyration_m:.3f} m"
        + (f", m = {body.mass_kg:.0f} kg, I = {body.inertia_kgm2:.0f} kg m^2"
           if mass_known else ", mass not given (no energies)")
        + (f", offset r_T = {offset:g} m (eccentric)" if offset else ""),
        f"contact  e_N = {e_n:.3f} ({e_source}), mu = "
        + ("inf (slip stops before separation: eqs. 4.20-4.22)"
           if math.isinf(friction) else f"{friction:g}"),
        "",
        f"{'':26s}{'impact':>10s}{'final':>10s}",
        f"{'v_T  tangential [m/s]':26s}{v_it:10.2f}{f['v_ft_mps']:10.2f}",
        f"{'v_N  normal [m/s]':26s}{v_in:10.2f}{f['v_fn_mps']:10.2f}",
        f"{'speed [m/s]':26s}{math.hypot(v_it, v_in):10.2f}{f['v_f_mps']:10.2f}",
        f"{'angle to ground [deg]':26s}"
        f"{math.degrees(math.atan2(-v_in, v_it)):10.2f}{f['theta_f_deg']:10.2f}",
        f"{'spin omega [rad/s]':26s}{spin:10.2f}{f['omega_f_radps']:10.2f}",
        f"{'slip v_T + r omega [m/s]':26s}{f['slip_velocity_i_mps']:10.2f}"
        f"{f['slip_velocity_f_mps']:10.2f}",
        f"{'e_N = -v_fN/v_iN':26s}{'':10s}{f['e_n']:10.3f}",
        f"{'e_T = v_fT/v_iT':26s}{'':10s}"
        + (f"{f['e_t']:10.3f}" if math.isfinite(f["e_t"])
           else "  not defined (v_iT = 0)"),
        "",
    ]  # fmt: skip
    unit = "N s" if mass_known else "N s/kg"
    slip = (
        f"slip stops at p_s = {f['p_slip_stop']:.1f} {unit} "
        f"(p_s/p_c = {f['p_slip_stop'] / f['p_c']:.3f}), then rolls"
        if res.slip_stops
        else "slip continues to separation"
    )
    lines += [
        f"impulses   p_c = {f['p_c']:.1f} {unit} (maximum compression), "
        f"p_f = {f['p_f']:.1f} {unit} (separation)",
        f"           {slip}",
    ]
    if mu_min is not None:
        lines.append(
            f"           slip stops before separation for mu >= {mu_min:.3f} (eq. C.26)"
        )
    if mass_known:
        kj = {k: v / 1e3 for k, v in f.items() if k.endswith("_j")}
        total_i = kj["ke_i_j"] + kj["re_i_j"]
        total_f = kj["ke_f_j"] + kj["re_f_j"]
        loss = -kj["energy_change_j"] / total_i * 100 if total_i else 0.0
        lines += [
            "",
            f"{'energy [kJ]':26s}{'impact':>10s}{'final':>10s}{'change':>10s}",
            f"{'kinetic KE':26s}{kj['ke_i_j']:10.1f}{kj['ke_f_j']:10.1f}"
            f"{kj['ke_f_j'] - kj['ke_i_j']:10.1f}",
            f"{'rotational RE':26s}{kj['re_i_j']:10.1f}{kj['re_f_j']:10.1f}"
            f"{kj['re_f_j'] - kj['re_i_j']:10.1f}",
            f"{'total':26s}{total_i:10.1f}{total_f:10.1f}{total_f - total_i:10.1f}"
            f"   ({loss:.1f} % lost)",
            f"work of the contact force: compression {kj['work_compression_j']:.1f}, "
            f"restitution {kj['work_restitution_j']:+.1f}, friction "
            f"{kj['work_friction_j']:.1f} kJ",
        ]  # fmt: skip
    return "\n".join(lines)


@one_line_errors(flags=_FLAGS)
def impact(
    speed: Annotated[
        float | None, typer.Option("--speed", help="Impact speed v_i (m/s).")
    ] = None,
    angle: Annotated[
        float | None,
        typer.Option("--angle", help="Impact angle theta_i to the ground (deg)."),
    ] = None,
    vt: Annotated[
        float | None,
        typer.Option(
            "--vt",
            help="Impact velocity along the ground v_iT (m/s), "
            "down-slope positive (instead of --speed/--angle).",
        ),
    ] = None,  # fmt: skip
    vn: Annotated[
        float | None,
        typer.Option("--vn", help="Impact velocity normal to the ground v_iN < 0."),
    ] = None,
    spin: Annotated[
        float,
        typer.Option(
            "--spin",
            help="Spin at impact omega_i (rad/s); negative = "
            "clockwise, the usual spin going down-slope (thesis Fig. 4.6).",
        ),
    ] = 0.0,  # fmt: skip
    mass: MassOpt = None,
    radius: RadiusOpt = None,
    gyration: GyrationOpt = None,
    shape: ShapeOpt = None,
    dimensions: DimensionsOpt = None,
    unit_weight: UnitWeightOpt = None,
    offset: Annotated[
        float,
        typer.Option(
            "--offset",
            help="Eccentric impact: tangential offset r_T of the "
            "centre of mass from the contact point (m) (App. C.11); 0 = "
            "collinear (sphere).",
        ),
    ] = 0.0,  # fmt: skip
    en: Annotated[
        float | None,
        typer.Option("--en", help="Normal coefficient of restitution e_N (>= 0)."),
    ] = None,
    law: Annotated[
        str | None,
        typer.Option(
            "--law",
            help="Restitution law: constant (--en), angle "
            "(e_N = a theta_i^-b, eq. 5.4) or velocity (--en scaled by "
            "1/(1+(v_iN/K)^2), eq. 7.1).",
        ),
    ] = None,  # fmt: skip
    a: Annotated[float, typer.Option("--a", help="eq. 5.4 factor a.")] = ANGLE_LAW_A,
    b: Annotated[float, typer.Option("--b", help="eq. 5.4 exponent b.")] = ANGLE_LAW_B,
    scale_velocity: Annotated[
        float,
        typer.Option("--scale-velocity", help="eq. 7.1 constant K (m/s)."),
    ] = VELOCITY_SCALE_MPS,
    friction: Annotated[
        float,
        typer.Option(
            "--friction",
            help="Friction coefficient mu at the contact; "
            "default inf = slip always stops before separation (eqs. "
            "4.20-4.22); 0 = smooth.",
        ),
    ] = math.inf,  # fmt: skip
    figure: Annotated[
        Path | None,
        typer.Option("--figure", help="Write the pN-v diagram (Figs. 4.4/4.5) as PNG."),
    ] = None,  # fmt: skip
    json_out: Annotated[
        Path | None, typer.Option("--json", help="Write inputs and results as JSON.")
    ] = None,
) -> None:
    r"""Impact of a rough, rotating rock on the slope: final velocities, spin, energies.

    Local axes at the impact: T along the ground down-slope, N out of the
    ground (v_iN < 0); spin negative = clockwise. Thesis ch. 4 and appendix C.

    Worked example 4A (1.5 m sphere, 22 m/s at 25 deg, spin -15 rad/s, e_N
    from eq. 5.4) gives v_fT 17.5, v_fN 6.6 m/s, omega_f -23.3 rad/s,
    theta_f 20.7 deg:

        fieldkit impact --speed 22 --angle 25 --spin -15 \
          --shape sphere --dimensions 0.75 --law angle

    With friction 0.5 (a slip phase), the pN-v diagram (Figs. 4.4/4.5) and
    the numbers as JSON:

        fieldkit impact --speed 22 --angle 25 --spin -15 \
          --shape sphere --dimensions 0.75 --law angle --friction 0.5 \
          --figure out/pnv.png --json out/impact.json
    """
    v_it, v_in = _impact_velocity(speed, angle, vt, vn)
    for value, flag, quantity in (
        (spin, "--spin", "spin_radps"),
        (en, "--en", "e_n"),
        (friction, "--friction", "friction"),
        (offset, "--offset", "length_m"),
        (a, "--a", "angle_law_a"),
        (b, "--b", "angle_law_b"),
        (scale_velocity, "--scale-velocity", "velocity_scale_mps"),
    ):
        check_physical(value, flag, quantity)
    body = body_from_options(
        mass, radius, gyration, shape, dimensions, unit_weight
    ).require(*BODY_NEEDS, source="fieldkit impact")
    outputs = OutputSet()
    for path, flag in ((figure, "--figure"), (json_out, "--json")):
        if path is not None:
            outputs.plan(path, argument=flag)
    mass_known = body.mass_kg is not None
    theta_i = math.degrees(math.atan2(-v_in, v_it))
    with np.errstate(over="ignore", divide="ignore"):  # refused just below
        e_n, e_source = _restitution(law, en, a, b, scale_velocity, theta_i, v_in)
    check_physical(e_n, f"e_N by {e_source} at theta_i {theta_i:.3g} deg", "e_n")
    common = {
        "radius_m": body.radius_m,
        "gyration_m": body.gyration_m,
        "e_n": e_n,
        "friction": friction,
        "offset_m": offset,
        "mass_kg": body.mass_kg,
    }
    res = rough_body_impact(v_it, v_in, spin, **common)
    history = impulse_history(v_it, v_in, spin, **common) if figure else None

    mu_min = None
    if offset == 0.0:
        mu_min = float(
            minimum_friction_to_stop_slip(
                v_it, v_in, spin, radius_m=body.radius_m, gyration_m=body.gyration_m,
                e_n=e_n,
            )
        )  # fmt: skip
    typer.echo(
        _report(res, body, v_it, v_in, spin, e_n, e_source, friction, offset, mu_min)
    )
    print_body_notes(body)
    k2 = body.gyration_m**2
    before = v_it**2 + v_in**2 + k2 * spin**2
    after = float(res.v_f_mps) ** 2 + k2 * float(res.omega_f_radps) ** 2
    if after > before * (1 + 1e-12):
        warn(
            f"the rock leaves with more energy than it arrived with (e_N = {e_n:.2f} "
            "> 1): the thesis's e_N > 1 at shallow impacts reflects eccentric "
            "geometry, which a collinear impact with this e_N does not model"
        )

    if figure is not None and history is not None:
        from fieldkit.viz.pnv_figure import save_pnv_figure

        mu_text = "\\infty" if math.isinf(friction) else f"{friction:g}"
        title = (
            f"$v_i$ = {math.hypot(v_it, v_in):.1f} m/s at {theta_i:.1f}°, "
            f"$\\omega_i$ = {spin:g} rad/s, $e_N$ = {e_n:.3f}, $\\mu$ = ${mu_text}$"
        )
        save_pnv_figure(
            history, figure, title=title,
            impulse_unit=None if mass_known else "N s/kg", outputs=outputs,
        )  # fmt: skip
    if json_out is not None:
        payload = {
            "inputs": {
                "v_it_mps": v_it, "v_in_mps": v_in, "theta_i_deg": theta_i,
                "omega_i_radps": spin, "e_n": e_n, "e_n_source": e_source,
                "friction": None if math.isinf(friction) else friction,
                "offset_m": offset,
            },
            "body": {
                "mass_kg": body.mass_kg if mass_known else None,
                "radius_m": body.radius_m, "gyration_m": body.gyration_m,
                "volume_m3": body.volume_m3, "shape": body.shape,
            },
            "results": {k: _number(v) for k, v in vars(res).items()},
            "minimum_friction_to_stop_slip": mu_min,
            "impulse_unit": "N s" if mass_known else "N s/kg",
        }  # fmt: skip
        write_json(json_out, payload, outputs)
    report_written(outputs.commit())
