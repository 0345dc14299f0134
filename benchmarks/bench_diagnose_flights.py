"""Flight-level diagnosis (`air_drag` from flights): power, false findings, time.

Synthetic tracks (:func:`fieldkit.fit.synthetic_track.synthetic_track`): a rock of
radius 0.2 m (sphere, 2650 kg/m^3, 88.8 kg) bouncing down a 35 deg plane, 8 flights
launched at the given mean speed (each within +-20 %) and 10-20 deg above the plane,
sampled at 200 frames/s with 5 mm Gaussian noise on x and z. For each drag size
(``cd`` x launch speed; the drag deceleration ``k v^2`` at the mean speed is shown)
50 tracks (seeds 0..49) are diagnosed from their true flights
(:func:`fieldkit.diagnose.flights.diagnose_flights`, 5 folds, rule
``scoring.DEFAULT_Z``): the share recommending ``air_drag`` (a false finding when
``cd = 0``), and the fitted ``cd`` (mean, and SD of ``(cd - truth) / SE``, which is 1
when the standard error is right). A smaller set goes through the command-line path
(CSV written, read, flights found by the tracking segmentation). Last, the wall time
of one diagnosis of 10 flights x ~100 samples.

First, the detection table of issue 22 from weak to strong drag, with and without
noise, on the video ball (:func:`fieldkit.tracking.flights.synthetic_tracks.
bouncing_ball`: 75 mm, 140 g, 1205 frames/s, 0.9 s, e_n 0.7 on a 15 deg plate, so
3 flights), through the whole track path: the segmentation finds flights and impacts
(surface angle given), `diagnose_track_file` the drag. Per row: impacts found
against the truth, impacts with e_n < 0, the largest |e_n error|, flights reported
as not ballistic, the share recommending air_drag and the mean fitted cd and gain.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from fieldkit.cli.diagnose_track import diagnose_track_file
from fieldkit.diagnose.flights import FlightSamples, diagnose_flights, sphere_mass_kg
from fieldkit.fit.synthetic_track import synthetic_track
from fieldkit.model.effects.air_drag import drag_factor
from fieldkit.tracking.flights.pipeline import analyse_track
from fieldkit.tracking.flights.synthetic_tracks import bouncing_ball

#: The video ball of video/render.py.
BALL_RADIUS_M, BALL_MASS_KG = 0.0375, 0.14
#: Tracks per row of the ball table.
BALL_TRACKS = 5

RADIUS_M = 0.2
MASS_KG = sphere_mass_kg(RADIUS_M)
TRACKS = 50


def make(seed: int, cd: float, speed: float, *, flights: int = 8, fps: float = 200.0):
    """One synthetic track (see the module docstring)."""
    rng = np.random.default_rng(seed)
    return synthetic_track(
        radius_m=RADIUS_M,
        mass_kg=MASS_KG,
        cd=cd,
        launch_speed_mps=speed * rng.uniform(0.8, 1.2, flights),
        launch_angle_deg=rng.uniform(10.0, 20.0, flights),
        surface_angle_deg=35.0,
        fps=fps,
        noise_m=0.005,
        rng=rng,
    )


def true_flights(track) -> list[FlightSamples]:
    """The flights of a synthetic track, from its ``flight_true`` column."""
    return [
        FlightSamples(g["t_s"].to_numpy(), g["x_m"].to_numpy(), g["z_m"].to_numpy())
        for _, g in track.frame.groupby("flight_true")
    ]


def rates(cd: float, speed: float) -> tuple[float, float, float]:
    """(share recommended, mean fitted cd, SD of the cd z-scores) over TRACKS."""
    found, fitted, z = 0, [], []
    for seed in range(TRACKS):
        d = diagnose_flights(
            true_flights(make(seed, cd, speed)),
            radius_m=RADIUS_M,
            mass_kg=MASS_KG,
            rng=np.random.default_rng(seed),
        )
        found += d.recommended == "air_drag"
        c = d.candidates[0]
        fitted.append(c.params["air_drag.cd"])
        z.append((c.params["air_drag.cd"] - cd) / c.params_sd["air_drag.cd"])
    return found / TRACKS, float(np.mean(fitted)), float(np.std(z))


def cli_rates(cd: float, speed: float, n: int = 20) -> float:
    """Share recommended through CSV + segmentation (diagnose_track_file)."""
    found = 0
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "track.csv"
        for seed in range(n):
            make(seed, cd, speed).write(path)
            d = diagnose_track_file(
                path,
                radius_m=RADIUS_M,
                mass_kg=MASS_KG,
                rng=np.random.default_rng(seed),
                folds=5,
            )
            found += d.recommended == "air_drag"
    return found / n


def timing() -> tuple[float, float, int]:
    """Best of 5: one diagnosis of 10 flights (~100 samples each), and the whole
    file path (read + segmentation + diagnosis)."""
    track = make(0, 0.5, 12.0, flights=10, fps=150.0)
    flights = true_flights(track)
    best, best_file = np.inf, np.inf
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "track.csv"
        track.write(path)
        for _ in range(5):
            start = time.perf_counter()
            diagnose_flights(flights, radius_m=RADIUS_M, rng=np.random.default_rng(0))
            best = min(best, time.perf_counter() - start)
            start = time.perf_counter()
            diagnose_track_file(
                path,
                radius_m=RADIUS_M,
                mass_kg=None,
                rng=np.random.default_rng(0),
                folds=5,
            )
            best_file = min(best_file, time.perf_counter() - start)
    return best, best_file, len(track)


def ball_row(cd: float, noise_m: float) -> dict:
    """One row of the ball table: BALL_TRACKS dragged bouncing balls (seeds 0..)."""
    row = dict(impacts=0, true=0, matched=0, negative=0, en_err=0.0, misfits=0, found=0)
    cds, gains = [], []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "track.csv"
        for seed in range(BALL_TRACKS):
            s = bouncing_ball(
                duration_s=0.9, start_xz_m=(0.0, 0.35), start_velocity_mps=(2.5, 0.5),
                surface_angle_deg=15.0, e_n=0.7, e_t=0.85, cd=cd,
                mass_kg=BALL_MASS_KG, noise_m=noise_m,
                rng=np.random.default_rng(seed), max_impacts=3,
            )  # fmt: skip
            a = analyse_track(
                s.track, radius_m=BALL_RADIUS_M, surface_angle_deg=15.0,
                mass_kg=BALL_MASS_KG,
            )  # fmt: skip
            f = a.impacts.frame[~a.net_rows]
            en = f["e_n"].to_numpy(float)
            # a found impact lies within a frame of a true one
            near = np.abs(f["t_s"].to_numpy()[:, None] - s.truth["t_s"].to_numpy())
            row["impacts"] += len(en)
            row["true"] += len(s.truth)
            row["matched"] += int((near.min(axis=0) < 1 / 1205).sum()) if len(en) else 0
            row["negative"] += int((en < 0).sum())
            if len(en) == len(s.truth):
                row["en_err"] = max(row["en_err"], float(np.abs(en - 0.7).max()))
            else:
                row["en_err"] = np.inf
            row["misfits"] += sum("not ballistic" in w for w in a.warnings)
            s.track.write(path)
            d = diagnose_track_file(
                path, radius_m=BALL_RADIUS_M, mass_kg=BALL_MASS_KG,
                rng=np.random.default_rng(seed), folds=5,
            )  # fmt: skip
            row["found"] += d.recommended == "air_drag"
            cds.append(d.candidates[0].params["air_drag.cd"])
            gains.append(d.candidates[0].improvement)
    row["cd"], row["gain"] = float(np.mean(cds)), float(np.mean(gains))
    return row


def ball_table() -> None:
    """The detection table on the video ball, weak to strong drag (issue 22)."""
    k_per_cd = float(drag_factor(1.0, 1.225, BALL_RADIUS_M, BALL_MASS_KG))
    print(
        f"video ball r = {BALL_RADIUS_M} m, m = {BALL_MASS_KG} kg, 1205 fps, 3 flights "
        f"on a 15 deg plate, e_n 0.7; {BALL_TRACKS} tracks per row; segmentation + "
        "diagnose_track_file"
    )
    print(
        "    cd  k v^2 at 2.5 m/s  noise mm  impacts/true/matched  e_n<0  max|de_n|  "
        "misfit flights  recommended  mean cd  mean gain"
    )
    for noise_m in (0.0001, 0.0005):
        for cd in (0.0, 0.1, 0.3, 1.0, 2.0, 3.0):
            r = ball_row(cd, noise_m)
            print(
                f"  {cd:4.1f}  {cd * k_per_cd * 2.5**2:16.4f}  {noise_m * 1e3:8.2f}  "
                f"{r['impacts']:8d}/{r['true']:2d}/{r['matched']:<8d}  "
                f"{r['negative']:5d}  "
                f"{r['en_err']:9.3f}  {r['misfits']:14d}  "
                f"{r['found'] / BALL_TRACKS:11.2f}  {r['cd']:7.2f}  {r['gain']:+9.1%}"
            )


def main() -> None:
    ball_table()
    per_cd = float(drag_factor(1.0, 1.225, RADIUS_M, MASS_KG))
    print(
        f"rock r = {RADIUS_M} m, m = {MASS_KG:.1f} kg, 8 flights, 200 fps, "
        f"5 mm noise, {TRACKS} tracks per row"
    )
    print(" speed  cd     k v^2 [m/s^2]  recommended  mean cd  sd z(cd)")
    for speed in (10.0, 15.0, 25.0):
        for cd in (0.0, 0.01, 0.02, 0.05, 0.1):
            share, mean_cd, sd_z = rates(cd, speed)
            print(
                f"{speed:6.0f}  {cd:5.2f}  {cd * per_cd * speed**2:13.4f}  "
                f"{share:11.2f}  {mean_cd:7.3f}  {sd_z:8.2f}"
            )
    print("through CSV + segmentation (20 tracks each, speed 15 m/s):")
    for cd in (0.0, 0.05, 0.3):
        print(f"  cd {cd:4.2f}: recommended {cli_rates(cd, 15.0):.2f}")
    t_one, t_file, n = timing()
    print(
        f"wall time, 10 flights ({n} samples): diagnose_flights {t_one * 1e3:.0f} ms, "
        f"diagnose_track_file {t_file * 1e3:.0f} ms"
    )


if __name__ == "__main__":
    main()
