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


def main() -> None:
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
