"""Diagnose the thesis case studies, and test eq. 5.4 against its spurious part.

For each survey of ``surveys/`` (thesis chapter 2) this script

1. reduces it with fieldkit's own reduction (``fieldkit reduce``: flights from tree
   strikes or the restitution angle, standard uncertainties ``*_sd`` propagated from
   the position error, 0.5 m per point and 0.25 m per tree-strike height);
2. runs :func:`fieldkit.diagnose.impacts.diagnose_impacts` (baseline: constant
   ``e_n``, ``e_t`` per material) on the impacts that have both an arriving and a
   leaving flight;
3. repeats the thesis's own analysis of eq. 5.4 (§5.2.3, Fig. 5.7: a power law
   ``e_n = a theta_i^-b`` fitted to ``log e_n`` against ``log theta_i``) and measures
   how much of the slope ``b`` survey error alone produces: ``e_n = vfn/|vin|`` and
   ``theta_i = atan(|vin|/vit)`` share ``vin``, so an error in ``vin`` moves them in
   opposite directions. The *null* keeps every impact's measured ``vin``, ``vit``,
   puts ``vfn``, ``vft`` on a constant ``e_n``, ``e_t`` per material (no angle or
   speed law at all) and adds the survey's own error: each draw moves every point and
   tree-strike height by the reduction's error model, re-solves every flight with
   :func:`fieldkit.reduce.pipeline.point_kinematics`, and adds the resulting change
   of ``vin``, ``vit``, ``vfn``, ``vft`` (correlated as the geometry makes them:
   neighbouring impacts share points and chords) to the null velocities. The naive
   slope refitted on each draw is the distribution of ``b`` with no angle law.
4. runs the diagnosis on a few such null tables too, to see how often it recommends
   an effect that is not there (its false-alarm rate on this geometry).

The Chant Sura impacts (Caviezel et al. 2019) give incoming speed and angle and the
energy before and after each impact, but not the rebound's normal and tangential
split: no ``vfn``, so no ``e_n``; they are summarised, not diagnosed.

Run:  python examples/diagnose_real_data.py [OUT_DIR] [--draws N] [--null-diagnoses N]
(OUT_DIR is accepted for the examples test and unused.)  The defaults (400 draws, 4
null diagnoses) take about 20 s; docs/real-data-diagnosis.md used 2000 and 40.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from fieldkit.diagnose.impacts import diagnose_impacts
from fieldkit.errors import FieldkitError
from fieldkit.impact_table import ImpactTable
from fieldkit.io.impacts import read_impacts
from fieldkit.io.preset import read_preset
from fieldkit.io.trees import read_trees
from fieldkit.physics.bodies import resolve_body
from fieldkit.physics.local_axes import angle_to_ground_deg, to_section
from fieldkit.reduce.pipeline import ReduceOptions, point_kinematics, reduce_path
from fieldkit.survey import Survey

REPO = Path(__file__).resolve().parents[1]
SURVEYS = REPO / "surveys"
CHANT_SURA = REPO / "tests" / "data" / "chant_sura_2019"
PRIMARY = ["vi_x_mps", "vi_z_mps", "vf_x_mps", "vf_z_mps"]
LOCAL = ["vin_mps", "vit_mps", "vfn_mps", "vft_mps"]
#: Thesis eq. 5.4: e_N = 19.5 theta_i^-1.03 (58 impacts of all five sites, Fig. 5.7).
THESIS_B = 1.03
SEED = 2024


@dataclass(frozen=True)
class Dataset:
    """One survey of ``surveys/`` and the ``fieldkit reduce`` options it needs."""

    name: str
    impacts: str
    body: dict
    theta0_deg: float | None = None
    trees: str | None = None
    path_id: str = ""
    thesis: str = ""
    extra: dict = field(default_factory=dict)


#: Boulder A's reduce options, stated once (``fieldkit reduce --preset``).
BOULDER_A = read_preset(SURVEYS / "tornado_mountain" / "boulder_a_preset.toml")

DATASETS = (
    Dataset(
        "tornado_mountain",
        "tornado_mountain/boulder_a_impacts.gpx",
        BOULDER_A.body(),
        theta0_deg=BOULDER_A.reduce["theta0_deg"],
        trees="tornado_mountain/boulder_a_trees.csv",
        path_id=BOULDER_A.reduce["path_id"],
        thesis="Table 2-4",
    ),
    Dataset(
        "ehime",
        "ehime/cube_section.csv",
        {"mass_kg": 520, "radius_m": 0.3, "gyration_m": 0.245},
        theta0_deg=30.0,
        path_id="ehime",
        thesis="Table 2-3",
    ),
    Dataset(
        "asphalt",
        "asphalt/asphalt_section.csv",
        {"mass_kg": 500, "radius_m": 0.36, "gyration_m": 0.295},
        path_id="asphalt",
        thesis="Table 2-5",
    ),
    Dataset(
        "kreuger_quarry",
        "kreuger_quarry/kreuger_section_ft.csv",
        {"mass_kg": 580, "radius_m": 0.3, "gyration_m": 0.245},
        path_id="kreuger",
        thesis="Table 2-2",
    ),
    Dataset(
        "mt_stephen",
        "mt_stephen/stephen_section.csv",
        {"mass_kg": 44, "radius_m": 0.2, "gyration_m": 0.13},
        path_id="mt_stephen",
        thesis="Table 2-1",
    ),
)


@dataclass
class Reduced:
    """A reduced survey: the table of impacts and what re-solves its flights."""

    dataset: Dataset
    survey: Survey
    options: ReduceOptions
    table: ImpactTable  # impacts with both flights (diagnosable rows)
    rows: np.ndarray  # their row numbers in the full reduction (= point order)
    dropped: list[str]  # points with no arriving or no leaving flight
    error_model: str


def reduce_dataset(ds: Dataset) -> Reduced:
    """``fieldkit reduce`` of ``ds`` (Python API), keeping the diagnosable rows."""
    points = read_impacts(SURVEYS / ds.impacts)
    trees = read_trees(SURVEYS / ds.trees, points) if ds.trees else None
    survey = Survey(points, trees)
    options = ReduceOptions(
        path_id=ds.path_id,
        theta0_deg=ds.theta0_deg,
        body=resolve_body(**ds.body),
    )
    red = reduce_path(survey, options)
    frame = red.table.frame
    ok = np.isfinite(frame[PRIMARY].to_numpy(float)).all(axis=1)
    table = ImpactTable(frame[ok].reset_index(drop=True), source=red.table.source)
    return Reduced(
        ds,
        survey,
        options,
        table,
        np.flatnonzero(ok),
        frame["point"][~ok].astype(str).tolist(),
        red.uncertainty.describe() if red.uncertainty else "none",
    )


def naive_slope(theta_deg: np.ndarray, e_n: np.ndarray) -> tuple[float, float, int]:
    """The thesis's fit: ``log e_n = log a - b log theta_i`` by least squares.

    Returns ``(b, se(b), n)`` over the rows with ``e_n > 0`` and ``theta_i > 0``
    (a log needs them; NaN with fewer than 3 rows).
    """
    ok = np.isfinite(theta_deg) & np.isfinite(e_n) & (theta_deg > 0) & (e_n > 0)
    n = int(ok.sum())
    if n < 3:
        return math.nan, math.nan, n
    x, y = np.log(theta_deg[ok]), np.log(e_n[ok])
    xc = x - x.mean()
    sxx = float(xc @ xc)
    if sxx <= 0:
        return math.nan, math.nan, n
    slope = float(xc @ (y - y.mean())) / sxx
    resid = y - y.mean() - slope * xc
    se = math.sqrt(float(resid @ resid) / (n - 2) / sxx) if n > 2 else math.nan
    return -slope, se, n


def error_draws(red: Reduced, draws: int, rng: np.random.Generator) -> np.ndarray:
    """Survey-error changes of ``vin, vit, vfn, vft`` at the table's impacts.

    Each draw moves every point by N(0, sigma) in x and z and every tree-strike
    height by N(0, sigma_h) (the reduction's own error model), re-solves all flights
    and returns the change from the surveyed values; draws in which a flight of the
    table's impacts has no ballistic solution are left out. Shape
    ``(used draws, n, 4)``.
    """
    err = red.options.position_error
    frame = red.survey.points.frame.reset_index(drop=True)
    x, z = frame["x_m"].to_numpy(float), frame["z_m"].to_numpy(float)
    heights = (
        None
        if red.survey.trees is None
        else red.survey.trees.frame["strike_height_m"].to_numpy(float)
    )
    nominal = point_kinematics(red.survey, red.options, x, z, heights)
    base = np.column_stack([nominal[c] for c in LOCAL])[red.rows]
    out = []
    for _ in range(draws):
        dx = rng.normal(0.0, err.position_sigma_m, x.shape)
        dz = rng.normal(0.0, err.elevation_sigma_m, z.shape)
        dh = (
            None
            if heights is None
            else heights + rng.normal(0.0, err.strike_height_sigma_m, heights.shape)
        )
        try:
            moved = point_kinematics(red.survey, red.options, x + dx, z + dz, dh)
        except FieldkitError:
            continue
        delta = np.column_stack([moved[c] for c in LOCAL])[red.rows] - base
        if not np.isfinite(delta).all():  # a flight of the table unsolved here
            continue
        out.append(delta)
    return np.array(out).reshape(-1, len(red.rows), 4)


def constant_law(
    table: ImpactTable, per_material: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Per-row ``e_n``, ``e_t``: each material's median (no angle or speed law), or
    with ``per_material=False`` one median for every impact."""
    f = table.frame
    mat = f["material"].astype(str) if per_material else pd.Series(0, f.index)
    e_n = f.groupby(mat)["e_n"].transform("median").to_numpy(float)
    e_t = f.groupby(mat)["e_t"].transform("median").to_numpy(float)
    return e_n, e_t


def null_local(
    table: ImpactTable, delta: np.ndarray, per_material: bool = True
) -> np.ndarray:
    """Null ``vin, vit, vfn, vft`` (n, 4) for one draw of survey error ``delta``."""
    vin, vit = table.column("vin_mps"), table.column("vit_mps")
    e_n, e_t = constant_law(table, per_material)
    truth = np.column_stack([vin, vit, e_n * np.abs(vin), e_t * vit])
    return truth + delta


def null_slopes(
    table: ImpactTable, deltas: np.ndarray, per_material: bool = False
) -> np.ndarray:
    """Naive eq. 5.4 slope ``b`` on each null draw.

    ``per_material=False`` (the survey-error null): one constant ``e_n`` for every
    impact, so any slope is made by the errors alone. ``True``: each material's
    own constant, so a slope also comes from materials met at different angles.
    """
    out = []
    for delta in deltas:
        vin, vit, vfn, _ = null_local(table, delta, per_material).T
        with np.errstate(divide="ignore", invalid="ignore"):
            e_n = np.where(vin < 0, vfn / -vin, np.nan)
        out.append(naive_slope(angle_to_ground_deg(vit, vin), e_n)[0])
    return np.array(out)


def null_table(table: ImpactTable, delta: np.ndarray) -> ImpactTable:
    """The table with its rebounds (and impact velocities) replaced by a null draw."""
    vin, vit, vfn, vft = null_local(table, delta).T
    slope = table.column("slope_deg")
    f = table.frame.copy()
    f["vi_x_mps"], f["vi_z_mps"] = to_section(vit, vin, slope)
    f["vf_x_mps"], f["vf_z_mps"] = to_section(vft, vfn, slope)
    keep = [c for c in f.columns if not c.startswith(("vin_", "vit_", "vfn_", "vft_"))]
    keep += [c for c in f.columns if c.endswith("_sd_mps") and c not in keep]
    derived = ImpactTable(f[keep], source=table.source + " (null draw)").derive()
    return derived


def pooled(reds: list[Reduced]) -> ImpactTable:
    """All surveys' impacts in one table (one path each), as the thesis pooled them."""
    frame = pd.concat([r.table.frame for r in reds], ignore_index=True)
    return ImpactTable(frame, source="pooled thesis case studies")


def fmt_gain(c: dict) -> str:
    """``effect +gain ± se (params)`` for one ranked candidate."""
    params = ", ".join(
        f"{k.split('.')[-1]} {v:.3g} ± {c['params_sd'].get(k, math.nan):.2g}"
        for k, v in c["params"].items()
    )
    mark = " meaningful" if c["meaningful"] else ""
    return (
        f"{c['effect']}: cv_rmse {c['cv_rmse_mps']:.3f} m/s, gain "
        f"{c['improvement']:+.3f} ± {c['improvement_se']:.3f}{mark} ({params})"
    )


def report(name: str, table: ImpactTable, args, rng: np.random.Generator, red=None):
    """Diagnose ``table``, test eq. 5.4 naively and against the null; print it."""
    n = len(table)
    print(f"\n=== {name}: {n} impacts ({', '.join(table.paths())})")
    f = table.frame
    mats = f["material"].astype(str).value_counts().sort_index()
    print("materials: " + ", ".join(f"{m} {k}" for m, k in mats.items()))
    row = {"dataset": name, "impacts": n}
    try:
        d = diagnose_impacts(table, rng=np.random.default_rng(SEED)).to_json()
    except FieldkitError as error:
        print(f"diagnosis refused: {error}")
        row.update(recommended="(refused)", error=str(error))
        d = None
    if d is not None:
        print(f"groups: {d['groups']}")
        print(f"baseline cv_rmse {d['baseline']['cv_rmse_mps']:.3f} m/s")
        for c in d["candidates"]:
            print("  " + fmt_gain(c))
        print(f"recommended: {d['recommended']}; confounded: {d['confounded']}")
        print(f"stopped: {d['stopped']}")
        print(f"unexplained: {d['unexplained'] or 'none'}")
        print(
            "skipped: "
            + "; ".join(f"{k} ({v[:60]}...)" for k, v in d["skipped"].items())
        )
        best = d["candidates"][0] if d["candidates"] else None
        angle = next(
            (
                c
                for c in d["candidates"]
                if c["effect"] == "angle_dependent_restitution"
            ),
            None,
        )
        row.update(
            baseline=d["baseline"]["cv_rmse_mps"],
            best=best["effect"] if best else None,
            best_gain=best["improvement"] if best else math.nan,
            best_se=best["improvement_se"] if best else math.nan,
            recommended=d["recommended"],
            confounded=d["confounded"],
            angle_gain=angle["improvement"] if angle else math.nan,
            angle_se=angle["improvement_se"] if angle else math.nan,
            angle_b=angle["params"].get("angle_dependent_restitution.b", math.nan)
            if angle
            else math.nan,
            angle_b_sd=angle["params_sd"].get("angle_dependent_restitution.b", math.nan)
            if angle
            else math.nan,
        )
    b, se, used = naive_slope(table.column("theta_i_deg"), table.column("e_n"))
    print(
        f"naive eq. 5.4 fit (thesis b = {THESIS_B}): b = {b:.2f} ± {se:.2f} "
        f"({used} impacts with e_n > 0)"
    )
    row.update(naive_b=b, naive_se=se)
    deltas = red if isinstance(red, np.ndarray) else None
    if deltas is None or len(deltas) == 0:
        print("null: no survey-error draws solved")
        return row
    mixed = null_slopes(table, deltas, per_material=True)
    mixed = mixed[np.isfinite(mixed)]
    slopes = null_slopes(table, deltas)
    slopes = slopes[np.isfinite(slopes)]
    if slopes.size < 10:
        print(f"null: the naive slope needs 3 impacts with e_n > 0 ({used} here)")
        return row
    lo, hi = np.percentile(slopes, [2.5, 97.5])
    frac = float(np.mean(slopes >= b)) if np.isfinite(b) else math.nan
    print(
        f"null (one constant e_n + survey error, {len(slopes)} draws): "
        f"b mean {slopes.mean():.2f}, 95 % {lo:.2f} to {hi:.2f}; "
        f"P(b_null >= b) = {frac:.3f}"
    )
    row.update(null_mean=slopes.mean(), null_lo=lo, null_hi=hi, null_p=frac)
    mlo, mhi = np.percentile(mixed, [2.5, 97.5])
    print(
        "null with each material's own constant e_n + survey error: b mean "
        f"{mixed.mean():.2f}, 95 % {mlo:.2f} to {mhi:.2f} (materials met at "
        "different angles make a slope too)"
    )
    row.update(mat_null_mean=mixed.mean(), mat_null_lo=mlo, mat_null_hi=mhi)
    if d is not None and args.null_diagnoses:
        recs = []
        for k in range(min(args.null_diagnoses, len(deltas))):
            t = null_table(table, deltas[k])
            dn = diagnose_impacts(t, rng=np.random.default_rng(SEED + k)).to_json()
            recs.append(dn["recommended"] or "none")
        counts = pd.Series(recs).value_counts()
        print(
            f"diagnosis on {len(recs)} null tables (no effect present): recommended "
            + ", ".join(f"{k} {v}" for k, v in counts.items())
        )
        row["null_recommended"] = dict(counts)
    return row


def chant_sura() -> None:
    """What the Chant Sura impacts hold, and why they cannot test eq. 5.4 here."""
    f = pd.read_csv(CHANT_SURA / "chant_sura_esurf_2019_impacts.csv")
    print(f"\n=== chant_sura_2019: {len(f)} impacts (Caviezel et al. 2019)")
    ratio = (
        f["observed_post_rebound_translational_j"]
        / f["observed_pre_impact_translational_j"]
    )
    for _, r in f.assign(ratio=ratio).iterrows():
        print(
            f"  {r['impact_id']}: v_i {r['incoming_total_speed_mps']:.1f} m/s, "
            f"theta_i {r['impact_angle_deg']:.1f} deg, E_out/E_in {r['ratio']:.2f}"
        )
    rho = pd.Series(f["impact_angle_deg"]).corr(ratio, method="spearman")
    print(
        "no rebound normal/tangential split (only E_out): no e_n, no vfn, so neither "
        "the diagnosis nor eq. 5.4 can be run; the impact normal speed itself is "
        f"inferred from jump height. Spearman rho(theta_i, E_out/E_in) = {rho:.2f} "
        "over 6 impacts (descriptive only)"
    )


def main() -> list[dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", help="unused (examples test)")
    parser.add_argument("--draws", type=int, default=400)
    parser.add_argument("--null-diagnoses", type=int, default=4)
    args = parser.parse_args()
    rng = np.random.default_rng(SEED)
    rows, reds, all_deltas = [], [], []
    for ds in DATASETS:
        red = reduce_dataset(ds)
        reds.append(red)
        print(
            f"\n--- {ds.name} ({ds.thesis}): reduced {len(red.table)} impacts; left "
            f"out {red.dropped} (no arriving or leaving flight); {red.error_model}"
        )
        deltas = error_draws(red, args.draws, rng)
        print(f"survey-error draws solved: {len(deltas)} of {args.draws}")
        all_deltas.append(deltas)
        rows.append(report(ds.name, red.table, args, rng, deltas))
        if ds.name == "tornado_mountain":  # one material: no material mix
            col = (red.table.frame["material"] == "colluvium").to_numpy()
            sub = ImpactTable(
                red.table.frame[col].reset_index(drop=True), source=red.table.source
            )
            rows.append(report("tornado_colluvium", sub, args, rng, deltas[:, col]))
    # Pooled, as the thesis pooled all sites for eq. 5.4 (errors independent between
    # surveys: a draw of each, as many draws as the survey with the fewest).
    k = min(len(d) for d in all_deltas)
    pooled_deltas = np.concatenate([d[:k] for d in all_deltas], axis=1)
    rows.append(report("pooled", pooled(reds), args, rng, pooled_deltas))
    chant_sura()
    print("\nsummary")
    print(pd.DataFrame(rows).drop(columns=["error"], errors="ignore").to_string())
    return rows


if __name__ == "__main__":
    main()
