"""What every command shares: one-line errors naming flags, and shared options.

Library code names the arguments of its functions (``mass_kg``), never command-line
flags (see :mod:`fieldkit.errors`); :data:`FLAGS` maps those names to the flags, and
:func:`one_line_errors`, :func:`warn` and :func:`note` show the flags instead -- but
only flags the running command has (:func:`command_flags`): an error raised while
``simulate`` reads a model file's DEM profile names the file and field, not
``profile --step``. :func:`one_line_errors` also refuses a non-finite number given to
any float option (``inf``, ``nan``) before the command runs, unless the option's own
default is infinite (``--friction``, default inf).
"""

from __future__ import annotations

import functools
import math
import re
import secrets
from collections.abc import Callable, Mapping
from typing import Annotated, ParamSpec, TypeVar, overload

import numpy as np
import typer

from fieldkit.errors import ArgumentError, FieldkitError
from fieldkit.physics.bodies import SHAPES, UNIT_WEIGHT_KN_M3, ResolvedBody
from fieldkit.physics.constants import (
    MAX_LENGTH_M,
    MAX_MASS_KG,
    MAX_SPEED_MPS,
    MIN_LENGTH_M,
    MIN_MASS_KG,
)

P = ParamSpec("P")
R = TypeVar("R")

#: Library argument names -> the command-line flags that set them. A command whose
#: flag for a name differs passes its own mapping to :func:`one_line_errors`.
FLAGS: dict[str, str] = {
    # the body (fieldkit.physics.bodies.resolve_body)
    "mass_kg": "--mass",
    "radius_m": "--radius",
    "gyration_m": "--gyration",
    "inertia_kgm2": "--inertia",
    "shape": "--shape",
    "dimensions_m": "--dimensions",
    "unit_weight_kn_m3": "--unit-weight",
    # survey reduction and its readers
    "theta0_deg": "--theta0",
    "units": "--units",
    "epsg": "--epsg",
    "gpx_points": "--gpx-points",
    "gpx_track": "--gpx-track",
    "declination_deg": "--declination",
    "friction": "--friction",
    "position_sigma_m": "--position-sigma",
    "elevation_sigma_m": "--position-sigma",
    "strike_height_sigma_m": "--height-sigma",
    # video tracking and track exports
    "fps": "--fps",
    "scale_points": "--scale-points",
    "scale_length_m": "--scale-length",
    "roi": "--roi",
    "first_box": "--first-box",
    "first_box_frame": "--first-box-frame",
    "body_colour_rgb": "--body-colour",
    "lens": "--lens",
    "pattern": "--pattern",
    "samples": "--samples",
    "surface_angle_deg": "--surface-angle",
    "unit": "--unit",
    "metres_per_pixel": "--metres-per-pixel",
    "file_fps": "--file-fps",
    "input_format": "--format",
    # the impact calculator
    "e_n": "--en",
    "offset_m": "--offset",
    "v_it_mps": "--vt",
    "v_in_mps": "--vn",
    "omega_i_radps": "--spin",
    "velocity_scale_mps": "--scale-velocity",
    # the fence calculator
    "speed_in_mps": "--speed-in",
    "angle_in_deg": "--angle-in",
    "spin_in_radps": "--spin-in",
    "speed_out_mps": "--speed-out",
    "angle_out_deg": "--angle-out",
    "spin_out_radps": "--spin-out",
    "impulse_ns": "--impulse",
    # DEM sections (fieldkit.model.dem_profile)
    "start_xy": "--from",
    "vertices_xy": "--from/--to",
    "spacing_m": "--step",
    "step_m": "--step",
    "max_length_m": "--max-length",
    "ranges": "--materials",
    # synthetic tables and fits (fieldkit.fit)
    "noise_fraction": "--noise",
    "paths": "--paths",
    "seed": "--seed",
    "report_dir": "--report",
}

_QUOTED = re.compile(r"`(\w+)`")


def _current_context():
    """The click context of the running command, or None outside one."""
    try:  # typer bundles its own click (typer >= 0.20)
        from typer._click.globals import get_current_context
    except ImportError:  # pragma: no cover - typer on the installed click
        from click import get_current_context
    return get_current_context(silent=True)


def _command_options(ctx) -> frozenset[str]:
    """Every option string (``--step``, ``-o``) of the context's command."""
    names: set[str] = set()
    for param in ctx.command.params:
        names.update(param.opts)
        names.update(getattr(param, "secondary_opts", ()))
    return frozenset(names)


def command_flags(mapping: Mapping[str, str] = FLAGS) -> dict[str, str]:
    """The part of ``mapping`` whose flags the running command has.

    An argument name maps to a flag only when the command being run has that flag
    (``"--from/--to"``: both; a description that is not a flag is kept); an error
    about any other name keeps its own source (the file and field the value came
    from). Outside a command line (a library
    call, a doctest) the whole mapping.

    Examples
    --------
    >>> command_flags({"step_m": "--step"})
    {'step_m': '--step'}
    """
    ctx = _current_context()
    if ctx is None:
        return dict(mapping)
    options = _command_options(ctx)
    return {
        name: flag
        for name, flag in mapping.items()
        if not flag.startswith("-")  # a description ("the impact angle (--angle)")
        or all(part in options for part in flag.split("/"))
    }


def _non_finite_option(ctx, values: Mapping[str, object]) -> str | None:
    """The first float option given a non-finite value, as a one-line message.

    An option may be infinite only when its default is (``--friction``: inf means
    slip always stops); NaN is never a value.
    """
    for param in ctx.command.params:
        if not param.opts or param.opts[0][:1] != "-" or param.name not in values:
            continue
        value = values[param.name]
        items = value if isinstance(value, (list, tuple)) else [value]
        default = param.default if isinstance(param.default, float) else 0.0
        for item in items:
            if not isinstance(item, float) or math.isfinite(item):
                continue
            if math.isinf(item) and item == default:
                continue
            flag = max(param.opts, key=len)
            return f"{flag} must be a finite number (got {item:g})"
    return None


def with_flags(text: str, flags: Mapping[str, str] = FLAGS) -> str:
    """Replace every argument name in backticks by its flag.

    Examples
    --------
    >>> with_flags("unit_weight_kn_m3 needs `shape`")
    'unit_weight_kn_m3 needs --shape'
    """
    return _QUOTED.sub(lambda m: flags.get(m.group(1), m.group(1)), text)


def _argument(exc: FieldkitError, flags: Mapping[str, str]) -> str | None:
    """The argument an error is about: its source, or the name a check begins with
    (``"e_n must be >= 0"``)."""
    if exc.source in flags:
        return exc.source
    head, _, rest = exc.message.partition(" ")
    if exc.source is None and head in flags and rest.startswith("must "):
        return head
    return None


def error_line(exc: FieldkitError, flags: Mapping[str, str] = FLAGS) -> str:
    """The error as the command line prints it: argument names become flags.

    Examples
    --------
    >>> from fieldkit.errors import ArgumentError
    >>> error_line(ArgumentError("gyration_m must be <= radius_m", source="gyration_m"))
    '--gyration must be <= --radius'
    >>> error_line(ArgumentError("lies outside the frame", source="roi"))
    '--roi: lies outside the frame'
    """
    message = with_flags(exc.message, flags)
    name = _argument(exc, flags)
    if name is None:
        source = exc.source
        if source and (message + " ").startswith(source + " "):
            source = None  # "step_m must be > 0", not "step_m: step_m must be > 0"
        parts = [source, exc.where]
    else:
        # about an argument: bare argument names (with an underscore, so never prose)
        # are flags too, and the message may begin with the argument's own name
        names = sorted((n for n in flags if "_" in n), key=len, reverse=True)
        if names:
            pattern = r"\b(" + "|".join(map(re.escape, names)) + r")\b"
            message = re.sub(pattern, lambda m: flags[m.group(1)], message)
        flag = flags[name]
        if (message + " ").startswith(name + " "):
            message = flag + message[len(name) :]
        parts = [None if message.startswith(flag) else flag, exc.where]
    return ": ".join([*(p for p in parts if p), message])


@overload
def one_line_errors(func: Callable[P, R]) -> Callable[P, R]: ...


@overload
def one_line_errors(
    *, flags: Mapping[str, str]
) -> Callable[[Callable[P, R]], Callable[P, R]]: ...


def one_line_errors(func=None, *, flags=None):
    """Turn :class:`FieldkitError` into ``error: <one line>`` on stderr, exit 1.

    Argument names in the error become flags (:func:`error_line`), through
    :data:`FLAGS` updated with ``flags`` (a command whose flags differ), restricted
    to the flags the running command has (:func:`command_flags`). Before the
    command runs, a non-finite value of a float option (``--mass inf``,
    ``--step nan``) is a usage error (exit 2), unless the option's default is
    infinite.
    """
    mapping = {**FLAGS, **(flags or {})}

    def decorate(command: Callable[P, R]) -> Callable[P, R]:
        @functools.wraps(command)
        def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
            ctx = _current_context()
            if ctx is not None:
                problem = _non_finite_option(ctx, kwargs)
                if problem is not None:
                    typer.echo(f"error: {problem}", err=True)
                    raise typer.Exit(2)
            try:
                return command(*args, **kwargs)
            except FieldkitError as exc:
                line = error_line(exc, command_flags(mapping))
                typer.echo(f"error: {line}", err=True)
                raise typer.Exit(1) from None

        return wrapper

    return decorate if func is None else decorate(func)


def warn(message: str) -> None:
    """Print a one-line warning to stderr (argument names in backticks as flags)."""
    text = with_flags(message, command_flags())
    typer.echo(f"warning: {' '.join(text.split())}", err=True)


def note(message: str) -> None:
    """Print a one-line note to stderr (argument names in backticks as flags)."""
    text = with_flags(message, command_flags())
    typer.echo(f"note: {' '.join(text.split())}", err=True)


def body_from_options(
    mass: float | None,
    radius: float | None,
    gyration: float | None,
    shape: str | None,
    dimensions: str | None,
    unit_weight: float | None,
    inertia: float | None = None,
) -> ResolvedBody:
    """The body the shared body options describe (one mapping of options to the
    arguments of :func:`fieldkit.physics.bodies.resolve_body` for every command)."""
    from fieldkit.physics.bodies import resolve_body

    for part in re.split(r"[,xX]", dimensions or ""):
        try:
            size = float(part)
        except ValueError:
            continue  # resolve_body says what is wrong with the text
        check_physical(size, "--dimensions", "dimensions_m")
    body = resolve_body(
        mass_kg=mass,
        radius_m=radius,
        gyration_m=gyration,
        inertia_kgm2=inertia,
        shape=shape,
        dimensions_m=dimensions,
        unit_weight_kn_m3=unit_weight,
    )
    derived = "the body's {} (from --shape and --dimensions)"
    for value, given, flag, name, quantity in (
        (body.mass_kg, mass, "--mass", "mass", "mass_kg"),
        (body.radius_m, radius, "--radius", "radius", "length_m"),
        (body.gyration_m, gyration, "--gyration", "radius of gyration", "length_m"),
    ):
        flag = flag if given is not None else derived.format(name)
        check_physical(value, flag, quantity)
        minimum, units = BODY_MINIMA[quantity]
        if value is not None and value < minimum:
            raise ArgumentError(
                f"{flag} must be at least {minimum:g} {units} (got {value:g}): a "
                "smaller body is sand, not a rock"
            )
    return body


def print_body_notes(body: ResolvedBody) -> None:
    """Print what the body's values say must be stated (overrides, measurements)."""
    for text in body.notes:
        note(text)


# Body options (SI units), resolved by fieldkit.physics.bodies.resolve_body.
MassOpt = Annotated[float | None, typer.Option("--mass", help="Body mass (kg).")]
RadiusOpt = Annotated[
    float | None, typer.Option("--radius", help="Contact radius r (m).")
]
GyrationOpt = Annotated[
    float | None,
    typer.Option("--gyration", help="Radius of gyration k (m); I = m k^2."),
]
InertiaOpt = Annotated[
    float | None,
    typer.Option(
        "--inertia", help="Moment of inertia I (kg m^2), instead of --gyration."
    ),
]
ShapeOpt = Annotated[
    str | None,
    typer.Option(
        "--shape",
        help=f"Body shape from thesis Table 4-1: {', '.join(SHAPES)} (gives k, volume, "
        "mass and contact radius; instead of --gyration; --mass overrides the "
        "computed mass, --radius the contact radius within the shape's range).",
    ),
]
DimensionsOpt = Annotated[
    str | None,
    typer.Option(
        "--dimensions",
        help="Shape dimensions (m), as 1.6,1.3,1.3 or 1.6x1.3x1.3: cube L; sphere r "
        "(radius); cylinder L,r; ellipsoid 2a,2b,2c (full axis lengths, rotating "
        "about c); block L1,L2,L3 (a block's principal lengths, any order: the "
        "ellipsoid of those axes rolling about the shortest).",
    ),
]
UnitWeightOpt = Annotated[
    float | None,
    typer.Option(
        "--unit-weight",
        help=f"Rock unit weight for --shape, kN/m3 (default {UNIT_WEIGHT_KN_M3:g}).",
    ),
]


#: Largest size of the quantities the impact and fence calculators take from the
#: command line: (limit, units, why). A value beyond is a typo or a unit slip (e_N
#: 1e308 for 0.8), refused rather than computed with; the sign and the lower end
#: are each calculator's own checks. An infinite friction is accepted (the
#: option's default: slip always stops).
PHYSICAL_LIMITS: dict[str, tuple[float, str, str]] = {
    "speed_mps": (
        MAX_SPEED_MPS, "m/s", "free fall from 500 m reaches 99 m/s; rockfall impacts "
        "are tens of m/s",
    ),
    "spin_radps": (
        1000.0, "rad/s", "a 0.1 m rock rolling at 100 m/s spins at 1000 rad/s",
    ),
    "e_n": (
        10.0, "", "measured e_N reach 1.5 at shallow impacts (thesis Table 2-4)",
    ),
    "friction": (
        100.0, "", "mu = 100 is a friction angle of 89.4 deg; give inf for slip "
        "that always stops",
    ),
    "mass_kg": (
        MAX_MASS_KG, "kg", "10,000 t (3,700 m3 of rock): beyond it a fall is a rock "
        "avalanche, not a rockfall",
    ),
    "length_m": (MAX_LENGTH_M, "m", "rockfall blocks are at most a few metres across"),
    "dimensions_m": (20.0, "m", "rockfall blocks are at most a few metres across"),
    "angle_deg": (180.0, "deg", "an angle between two directions"),
    "impulse_ns": (1e9, "N s", "10,000 t at 100 m/s"),
    "angle_law_a": (1000.0, "", "eq. 5.4's a is 19.5 in the thesis"),
    "angle_law_b": (10.0, "", "eq. 5.4's b is 1.03 in the thesis"),
    "velocity_scale_mps": (1000.0, "m/s", "eq. 7.1's K is 9.144 m/s in the thesis"),
}  # fmt: skip


#: Smallest body the calculators take: (minimum, units). Below a gram or a
#: millimetre a "rock" is sand, and k^2 of 1e-300 m underflows to zero.
BODY_MINIMA: dict[str, tuple[float, str]] = {
    "mass_kg": (MIN_MASS_KG, "kg"),
    "length_m": (MIN_LENGTH_M, "m"),
}


def check_physical(value: float | None, flag: str, quantity: str) -> None:
    """Refuse ``value`` of ``flag`` larger in size than :data:`PHYSICAL_LIMITS`
    [quantity] (None: not given; an infinite friction passes, see there).

    Examples
    --------
    >>> check_physical(1e308, "--en", "e_n")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fieldkit.errors.ArgumentError: --en must be at most 10 in size (got 1e+308): ...
    """
    if value is None or (quantity == "friction" and value == math.inf):
        return
    limit, units, why = PHYSICAL_LIMITS[quantity]
    if not (math.isfinite(value) and abs(value) <= limit):
        raise ArgumentError(
            f"{flag} must be at most {limit:g}{' ' + units if units else ''} in size "
            f"(got {value:g}): {why}"
        )


#: Largest seed: numpy's generators take any non-negative integer; 2**128 - 1 is
#: the entropy of their seed sequence (more digits change nothing).
MAX_SEED = 2**128 - 1


def random_generator(seed: int | None) -> tuple[np.random.Generator, int]:
    """The generator of a command's ``--seed``, and the seed used.

    None draws a seed and says so (a note with the ``--seed`` that reproduces the
    run); a negative seed, or one above :data:`MAX_SEED`, is refused.
    """
    if seed is None:
        seed = secrets.randbits(32)
        note(f"`seed` not given: used {seed}; pass --seed {seed} to reproduce")
    elif not 0 <= seed <= MAX_SEED:
        raise ArgumentError(
            f"seed must be an integer from 0 to 2**128 - 1 (got {seed})", source="seed"
        )
    return np.random.default_rng(seed), seed


def parse_point(text: str, flag: str) -> tuple[float, float]:
    """``"X,Y"`` -> (x, y); a one-line error naming the flag otherwise."""
    parts = text.replace(";", ",").split(",")
    try:
        x, y = (float(p) for p in parts)
    except ValueError:
        raise ArgumentError(
            f"{flag} '{text}' is not X,Y (two numbers in metres, e.g. 30.6,235.3)"
        ) from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise ArgumentError(f"{flag} '{text}' must be finite numbers")
    return x, y
