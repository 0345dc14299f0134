"""How much a diagnosis's verdict hangs on choices made before it (issue 18 item 4).

A surveyed path's rebound velocities are not measured: the reduction solves each
flight between two surveyed points, and where no tree strike or given angle fixes
the parabola it *assumes* the launch angle to the ground ``theta0`` (the thesis
32.6°). On such a path the rebound normal speed tracks the next chord, which can
pass for a speed law. The verdict is therefore re-derived under variants of those
choices, with the same fold seed and options:

* ``theta0 - 10 deg`` and ``theta0 + 10 deg``: every flight whose ``theta0`` was
  assumed (``theta0_source == "assumed"``) is solved again from the ``x, z`` of its
  two points with ``alpha = theta0 + delta - psi`` (``psi`` the row's
  ``slope_deg`` at the launch point; a release flight with no slope there keeps
  the reduction's least-speed angle, shifted by ``delta``), and the impact and
  rebound velocities of the rows it joins are recomputed
  (:func:`fieldkit.impact_table.restitution` through ``derive``). Tree and given
  flights are unchanged. A flight no ballistic path makes at the shifted angle
  becomes unknown (its rows are left out as the ends of a path are) and is counted.
* ``materials grouped``: every material of the table as one (a table with more
  than one material), so a verdict that rests on how the ground was split shows.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from fieldkit.diagnose.diagnosis import Diagnosis
from fieldkit.errors import FieldkitError
from fieldkit.impact_table import ImpactTable
from fieldkit.model.model_file import Model
from fieldkit.physics.flight import flight_between
from fieldkit.reduce.flights import least_speed_launch_angle_deg

#: Shift of the assumed launch angle in the theta0 variants [deg].
THETA0_SHIFT_DEG = 10.0
#: Name of the one material of the grouped variant.
GROUPED = "all_materials"


@dataclass
class Variant:
    """The verdict of one diagnosis of a variant of the table."""

    variant: str
    description: str
    recommended: str | None
    accepted: list[str]
    best: str | None  # best candidate of the first round
    gain: float  # its held-out gain (1 - cv / cv_baseline)
    gain_se: float
    unsolved_flights: int = 0
    error: str = ""  # why the variant could not be diagnosed ("" when it was)

    def to_json(self) -> dict:
        """Plain dict (the JSON's ``sensitivity`` entries)."""
        return {
            "variant": self.variant,
            "description": self.description,
            "recommended": self.recommended,
            "accepted": list(self.accepted),
            "best": self.best,
            "gain": self.gain if math.isfinite(self.gain) else None,
            "gain_se": self.gain_se if math.isfinite(self.gain_se) else None,
            "unsolved_flights": int(self.unsolved_flights),
            "error": self.error,
        }

    def sentence(self) -> str:
        """The verdict in one line (the printed summary, the report)."""
        if self.error:
            return f"{self.variant}: not diagnosed: {self.error}"
        verdict = (
            "accepted " + ", ".join(self.accepted)
            if self.accepted
            else ("nothing recommended")
        )
        best = (
            f"; best {self.best} gain {self.gain:+.1%} ± {self.gain_se:.1%}"
            if self.best
            else ""
        )
        unsolved = (
            f"; {self.unsolved_flights} flight(s) without a ballistic solution left out"
            if self.unsolved_flights
            else ""
        )
        return f"{self.variant}: {self.description}: {verdict}{best}{unsolved}"


def is_surveyed(table: ImpactTable) -> bool:
    """True when some rebound of ``table`` was solved with an assumed ``theta0``.

    The flight from a path's release is "assumed" too (the least-speed launch),
    but its ``theta0`` is empty (no ground slope at the source) and it assumes no
    rebound angle: a table whose only assumed flight is that one (Ehime's, where
    every rebound angle was measured) is not a survey with assumed angles."""
    frame = table.frame
    if "theta0_source" not in frame:
        return False
    assumed = (frame["theta0_source"].astype("string") == "assumed").fillna(False)
    finite = np.isfinite(frame["theta0_deg"].to_numpy(float))
    return bool((assumed.to_numpy(bool) & finite).any())


def shifted_theta0(table: ImpactTable, delta_deg: float) -> tuple[ImpactTable, int]:
    """``(table, unsolved)``: ``table`` with every assumed-``theta0`` flight solved
    again at ``theta0 + delta_deg`` (module docstring); ``unsolved`` counts the
    flights no ballistic path makes at that angle (their velocities become NaN).

    Rows are the points of each path in order (``path_id``); row ``j``'s
    ``vf`` and row ``j + 1``'s ``vi`` are the flight leaving ``j``. Estimated spins
    (``omega_source == "estimated"``, rolling at the launch speed) follow the new
    speeds.
    """
    f = table.frame.copy()
    n = len(f)
    src = f["theta0_source"].astype("string").fillna("").to_numpy(str)
    path = (
        f["path_id"].astype("string").fillna("").to_numpy(str)
        if "path_id" in f
        else np.full(n, "")
    )
    x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
    psi = f["slope_deg"].to_numpy(float)
    theta0 = f["theta0_deg"].to_numpy(float)
    velocities = ("vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps")
    cols = {c: f[c].to_numpy(float).copy() for c in velocities}
    estimated = (
        (f["omega_source"].astype("string") == "estimated").fillna(False).to_numpy(bool)
        if "omega_source" in f
        else np.zeros(n, bool)
    )
    radius = f["radius_m"].to_numpy(float)
    omega_f = f["omega_f_radps"].to_numpy(float).copy()
    omega_i = f["omega_i_radps"].to_numpy(float).copy()
    unsolved = 0
    for j in range(n - 1):
        if src[j] != "assumed" or path[j] != path[j + 1]:
            continue
        dx, dz = float(x[j + 1] - x[j]), float(z[j + 1] - z[j])
        if math.isfinite(theta0[j]) and math.isfinite(psi[j]):
            alpha = theta0[j] + delta_deg - psi[j]
        else:  # a release flight: the reduction's least-speed launch
            alpha = least_speed_launch_angle_deg(dx, dz) + delta_deg
        try:
            fl = flight_between(dx, dz, alpha)
            vf = (float(fl.launch_vx_mps), float(fl.launch_vz_mps))
            vi = (float(fl.arrival_vx_mps), float(fl.arrival_vz_mps))
        except FieldkitError:
            unsolved += 1
            vf = vi = (math.nan, math.nan)
        cols["vf_x_mps"][j], cols["vf_z_mps"][j] = vf
        cols["vi_x_mps"][j + 1], cols["vi_z_mps"][j + 1] = vi
        if estimated[j]:
            omega_f[j] = -math.hypot(*vf) / radius[j]
        if estimated[j + 1]:
            omega_i[j + 1] = omega_f[j]
    for name, values in cols.items():
        f[name] = values
    f["omega_f_radps"], f["omega_i_radps"] = omega_f, omega_i
    return ImpactTable(f, source=table.source).derive(), unsolved


def grouped_materials(
    table: ImpactTable, model: Model | None
) -> tuple[ImpactTable, Model | None]:
    """``table`` with every material named :data:`GROUPED`, and ``model`` with
    that material added (the material most rows are on: a starting value the
    diagnosis refits)."""
    f = table.frame.copy()
    labels = f["material"].astype("string")
    f["material"] = labels.where(labels.isna(), GROUPED).astype("string")
    if model is not None:
        most = str(labels.value_counts().index[0])
        materials = {**model.materials, GROUPED: model.materials[most]}
        model = replace(model, materials=materials)
    return ImpactTable(f, source=table.source), model


def verdict(
    name: str, description: str, diagnosis: Diagnosis, unsolved: int = 0
) -> Variant:
    """The verdict of ``diagnosis`` as a :class:`Variant`."""
    best = diagnosis.candidates[0] if diagnosis.candidates else None
    return Variant(
        variant=name,
        description=description,
        recommended=diagnosis.recommended,
        accepted=diagnosis.accepted,
        best=best.effect if best else None,
        gain=best.improvement if best else math.nan,
        gain_se=best.improvement_se if best else math.nan,
        unsolved_flights=unsolved,
    )


def variants(table: ImpactTable) -> list[str]:
    """The variants :func:`sensitivity` runs on ``table`` (empty: none apply)."""
    out = []
    if is_surveyed(table):
        out += ["theta0 - 10 deg", "theta0 + 10 deg"]
    materials = table.frame["material"].astype("string").dropna().unique()
    if len(materials) > 1:
        out.append("materials grouped")
    return out


def sensitivity(
    table: ImpactTable,
    model: Model | None,
    diagnose: Callable[[ImpactTable, Model | None], Diagnosis],
) -> list[Variant]:
    """The verdict of every variant of ``table`` (:func:`variants`).

    ``diagnose(table, model)`` runs one diagnosis with the caller's seed and
    options (the same as the verdict being checked). A variant that cannot be
    diagnosed (too few impacts left, ...) keeps the reason in ``error``.
    """
    out: list[Variant] = []
    names = variants(table)
    assumed = (
        table.frame["theta0_source"].astype("string") == "assumed"
        if ("theta0_source" in table.frame)
        else None
    )
    for name in names:
        if name.startswith("theta0"):
            delta = -THETA0_SHIFT_DEG if "-" in name else THETA0_SHIFT_DEG
            values = table.frame["theta0_deg"][assumed.fillna(False)].dropna()
            was = sorted({round(float(v), 6) for v in values})
            said = ", ".join(f"{v + delta:.1f}°" for v in was[:3])
            said += ", ..." if len(was) > 3 else ""
            description = (
                f"the {int(assumed.fillna(False).sum())} flights with an assumed "
                f"launch angle re-solved at theta0 {said or '-'} instead of "
                + ", ".join(f"{v:.1f}°" for v in was[:3])
            )
            variant_table, unsolved = shifted_theta0(table, delta)
            variant_model = model
        else:
            materials = table.frame["material"].astype("string").dropna().unique()
            description = (
                f"the {len(materials)} materials {', '.join(sorted(materials))} as one"
            )
            variant_table, variant_model = grouped_materials(table, model)
            unsolved = 0
        try:
            diagnosis = diagnose(variant_table, variant_model)
        except FieldkitError as exc:
            out.append(
                Variant(
                    name,
                    description,
                    None,
                    [],
                    None,
                    math.nan,
                    math.nan,
                    unsolved,
                    exc.message,
                )  # fmt: skip
            )
            continue
        out.append(verdict(name, description, diagnosis, unsolved))
    return out
