"""One rock at a time in the Python interpreter: the benchmark baseline and cross-check.

:func:`simulate_one_rock` runs the *same source* as the compiled kernel
(:func:`fieldkit.model.kernel.run_rock` and its stages ``fly``, ``impact``,
``slide``, through numba's ``py_func``) in the Python interpreter, with the same
random numbers: for the same model, key and start it returns the same impacts as
:func:`fieldkit.model.simulate.simulate` (tests check agreement to 1e-12). Small
helpers it calls (root finding, random streams, effect hooks) stay compiled.
:func:`simulate_reference` draws starts and keys exactly as ``simulate`` does, so
``simulate_reference(model, n, default_rng(s))`` reproduces ``simulate(model, n,
default_rng(s))`` rock by rock, at interpreter speed.

An analytic reference written independently of this code lives in the tests
(tests/model/test_reference_agreement.py).
"""

from __future__ import annotations

import types
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import fieldkit.model.kernel as kernel
from fieldkit.model.model_file import Model
from fieldkit.model.simulate import body_of, draw_rocks, kernel_inputs


@dataclass(frozen=True)
class OneRock:
    """One rock's outcome: impact rows (columns :data:`kernel.RECORD_COLUMNS`)."""

    impacts: np.ndarray  # (n, N_RECORD)
    state: int
    runout_x_m: float

    def column(self, name: str) -> np.ndarray:
        """One column of :attr:`impacts` by name (e.g. ``"vf_x_mps"``)."""
        return self.impacts[:, kernel.RECORD_COLUMNS.index(name)]


#: The kernel's functions the reference interprets: the driver and its stages
#: (the helpers they call -- contact, sweeps, laws -- run compiled).
INTERPRETED = ("run_rock", "_drive", "fly", "impact", "slide")


def _interpreted_run_rock() -> Callable:
    """:func:`kernel.run_rock`'s Python source, calling the Python source of the
    other functions :data:`INTERPRETED`."""
    names = dict(vars(kernel))
    for name in INTERPRETED:
        py = getattr(kernel, name).py_func
        names[name] = types.FunctionType(py.__code__, names, name, py.__defaults__)
    return names["run_rock"]


def simulate_one_rock(
    model: Model,
    key: int | np.uint64,
    *,
    x_m: float,
    z_m: float,
    vx_mps: float = 0.0,
    vz_mps: float = 0.0,
    omega_radps: float = 0.0,
    mass_kg: float | None = None,
) -> OneRock:
    """Follow one rock with random key ``key`` from the given start (interpreted).

    Examples
    --------
    >>> from fieldkit.model.model_file import model_from_dict
    >>> m = model_from_dict({"profile": {"x_m": [0, 100], "z_m": [0, 0],
    ...   "material": "r"}, "materials": {"r": {"e_n": 0.5, "e_t": 1.0,
    ...   "friction_deg": 30}}, "body": {"mass_kg": 1, "radius_m": 0.1},
    ...   "seeder": {"x_m": 0, "z_m": 5}})
    >>> one = simulate_one_rock(m, 1, x_m=0.0, z_m=5.0, vx_mps=1.0)
    >>> round(float(one.column("vi_z_mps")[0]), 4)  # -sqrt(2 g 5)
    -9.9045
    """
    inputs = kernel_inputs(model)
    mass = model.body.mass_kg if mass_kg is None else float(mass_kg)
    radius, gyration = body_of(model, np.array([mass]))
    max_impacts = int(inputs.model.core.max_impacts)
    rec = np.zeros((max_impacts, kernel.N_RECORD))
    rock = kernel.Rock(
        np.uint64(key),
        float(x_m),
        float(z_m),
        float(vx_mps),
        float(vz_mps),
        float(omega_radps),
        mass,
        float(radius[0]),
        float(gyration[0]),
    )
    probe = kernel.Probe(
        np.zeros(0),
        np.full((0, kernel.N_ANALYSIS), np.nan),
        float(inputs.model.profile.x_m[0]),
        1.0,
        np.zeros(0, np.float32),
    )
    n, state, runout, _ = _interpreted_run_rock()(
        rock, inputs.model, probe, kernel.Record(rec, 0, True), np.zeros((0, 2))
    )
    return OneRock(impacts=rec[:n].copy(), state=int(state), runout_x_m=float(runout))


def simulate_reference(
    model: Model, rocks: int, rng: np.random.Generator
) -> list[OneRock]:
    """``rocks`` rocks drawn exactly as :func:`simulate` draws them, interpreted."""
    starts, keys = draw_rocks(model, rocks, rng)
    return [
        simulate_one_rock(
            model,
            keys[i],
            x_m=starts.x_m[i],
            z_m=starts.z_m[i],
            vx_mps=starts.vx_mps[i],
            vz_mps=starts.vz_mps[i],
            omega_radps=starts.omega_radps[i],
            mass_kg=starts.mass_kg[i],
        )
        for i in range(rocks)
    ]
