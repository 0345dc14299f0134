"""`fieldkit track` on a known ground: a slope per impact from a profile or a DEM.

A ball (r = 37.5 mm) is rendered bouncing down a surveyed section of two segments,
dipping 10 deg and then 30 deg, with exact truth (e_n 0.6 then 0.55, e_t 0.8 then
0.75 on each segment's own axes). Reduced on the section's own slope at each impact
(``--surface-profile``, or ``--surface-dem`` with ``--section``) e_n and e_t come back
within 0.005 (measured: 1e-4); one mean slope for the track (``--surface-angle 20``)
puts them off by
0.4 to 0.6: the slope at each impact is what makes them right.
"""

from __future__ import annotations

import importlib.util
import math
import sys

import numpy as np
import pandas as pd
import pytest

G = 9.81
FPS = 600.0
FRAMES = 300
RADIUS_M = 0.0375
#: Profile vertices (x, z) [m] in the clip's world frame: 10 deg, then 30 deg.
KINK_X_M = 0.45
DIPS_DEG = (10.0, 30.0)
LAWS = ((0.6, 0.8), (0.55, 0.75))  # (e_n, e_t) at the first and second impact
#: The DEM is this section extruded across, in plan coordinates E = x + E0, any N.
E0_M, N0_M, DEM_CELL_M = 100.0, 200.0, 0.05


def profile_vertices() -> tuple[np.ndarray, np.ndarray]:
    x = np.array([-0.2, KINK_X_M, 1.5])
    z = np.empty(3)
    z[0] = 0.30
    z[1] = z[0] - math.tan(math.radians(DIPS_DEG[0])) * (x[1] - x[0])
    z[2] = z[1] - math.tan(math.radians(DIPS_DEG[1])) * (x[2] - x[1])
    return x, z


def _signed_distance(p: np.ndarray) -> tuple[float, int]:
    """Distance of ``p`` from the profile (positive above) and the nearest segment."""
    px, pz = profile_vertices()
    best = (math.inf, 0)
    for i in range(2):
        a = np.array([px[i], pz[i]])
        d = np.array([px[i + 1] - px[i], pz[i + 1] - pz[i]])
        q = a + np.clip((p - a) @ d / (d @ d), 0.0, 1.0) * d
        up = (p - q) @ np.array([-d[1], d[0]])
        dist = math.copysign(float(np.hypot(*(p - q))), up)
        if abs(dist) < abs(best[0]):
            best = (dist, i)
    return best


def bounce_on_profile() -> tuple[np.ndarray, list[dict]]:
    """Poses ``(x, z, angle)`` per frame and the true impacts (exact to 1e-12 s)."""
    t = np.arange(FRAMES) / FPS
    poses = np.full((FRAMES, 3), np.nan)
    t0, p, v, omega, angle = (
        0.0,
        np.array([0.0, 0.40]),
        np.array([2.0, -0.5]),
        -20.0,
        0.3,
    )
    impacts = []
    for k in range(len(LAWS) + 1):

        def position(s, p=p, v=v):
            return p + v * s + 0.5 * np.array([0.0, -G]) * s * s

        hit = None
        if k < len(LAWS):
            s = 2e-4
            while _signed_distance(position(s))[0] >= RADIUS_M:
                s += 1e-4
            lo, hi = s - 1e-4, s
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                lo, hi = (
                    (lo, mid)
                    if _signed_distance(position(mid))[0] < RADIUS_M
                    else (mid, hi)
                )
            hit = hi
        end = t0 + hit if hit is not None else math.inf
        flight = (t >= t0) & (t < end)
        for j in np.flatnonzero(flight):
            poses[j, :2] = position(t[j] - t0)
            poses[j, 2] = angle + omega * (t[j] - t0)
        if hit is None:
            break
        segment = _signed_distance(position(hit))[1]
        psi = math.radians(DIPS_DEG[segment])
        n = np.array([math.sin(psi), math.cos(psi)])
        tangent = np.array([math.cos(psi), -math.sin(psi)])
        vi = v + np.array([0.0, -G]) * hit
        e_n, e_t = LAWS[k]
        vf = -e_n * (vi @ n) * n + e_t * (vi @ tangent) * tangent
        impacts.append(dict(t_s=t0 + hit, segment=segment, vi=vi, vf=vf))
        angle, omega = angle + omega * hit, -(vf @ tangent) / RADIUS_M
        t0, p, v = t0 + hit, position(hit), vf
    return poses, impacts


def write_dem(path, offset_m: float = 0.0):
    """The section extruded across, z(E, N) = profile(E - E0) + offset, 0.05 m cells."""
    px, pz = profile_vertices()
    e = np.arange(-0.3, 1.4, DEM_CELL_M)
    rows = 8
    z_row = np.interp(e + 0.5 * DEM_CELL_M, px, pz) + offset_m
    path.write_text(
        f"ncols {len(e)}\nnrows {rows}\nxllcorner {E0_M + e[0]}\n"
        f"yllcorner {N0_M - rows * DEM_CELL_M / 2}\ncellsize {DEM_CELL_M}\n"
        "NODATA_value -9999\n"
        + "\n".join(" ".join(f"{v:.9f}" for v in z_row) for _ in range(rows))
        + "\n"
    )
    return path


@pytest.fixture(scope="module")
def render(repo):
    name = "fieldkit_video_render_for_ground"
    spec = importlib.util.spec_from_file_location(name, repo / "video" / "render.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _render_clip(render, path, poses):
    camera = render.Camera(width=560, height=300, origin_u_px=40.0, origin_v_px=225.0)
    rng = np.random.default_rng(7)
    plate_away = render.BounceScene(plate_point_m=(0.0, -5.0))  # not drawn in view
    bg = np.clip(render.background(camera, rng, plate_away) + 0.5, 0, 255)
    return render.write_clip(
        path, camera, render.Ball(), bg.astype(np.uint8), poses, rng
    )


@pytest.fixture(scope="module")
def scene(render, tmp_path_factory):
    """The rendered clip, its homography, the profile CSV and the DEM."""
    folder = tmp_path_factory.mktemp("ground")
    poses, impacts = bounce_on_profile()
    assert [i["segment"] for i in impacts] == [0, 1]
    assert impacts[-1]["t_s"] < (FRAMES - 60) / FPS  # a flight after the 2nd impact
    video = _render_clip(render, folder / "ground.avi", poses)
    corners = [(40, 225), (540, 225), (540, 25), (40, 25)]
    homography = folder / "h.csv"
    homography.write_text(
        "u_px,v_px,x_m,z_m\n"
        + "\n".join(
            f"{u},{v},{(u - 40) * 0.002},{(225 - v) * 0.002}" for u, v in corners
        )
    )
    px, pz = profile_vertices()
    profile = folder / "profile.csv"
    profile.write_text(
        "x_m,z_m\n" + "\n".join(f"{x:.9f},{z:.9f}" for x, z in zip(px, pz, strict=True))
    )
    dem = write_dem(folder / "dem.asc")
    return dict(
        video=video, homography=homography, profile=profile, dem=dem, truth=impacts
    )


def _track(cli, scene, tmp_path, *ground):
    out = tmp_path / "impacts.csv"
    result = cli(
        "track", scene["video"], "--fps", FPS, "--homography", scene["homography"],
        "--radius", RADIUS_M, "--impacts", out, *ground,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    return pd.read_csv(out), result


def _true_restitution(truth: dict, slope_deg: float) -> tuple[float, float]:
    """e_n, e_t of a true impact decomposed on a surface dipping ``slope_deg``."""
    psi = math.radians(slope_deg)
    n = np.array([math.sin(psi), math.cos(psi)])
    tangent = np.array([math.cos(psi), -math.sin(psi)])
    vi, vf = truth["vi"], truth["vf"]
    return -(vf @ n) / (vi @ n), (vf @ tangent) / (vi @ tangent)


def _check_per_impact(table: pd.DataFrame, truth: list[dict], source: str) -> None:
    assert len(table) == 2
    np.testing.assert_allclose(table["slope_deg"], DIPS_DEG, atol=0.01)
    assert table["slope_source"].tolist() == [source, source]
    for (_, row), true, (e_n, e_t) in zip(table.iterrows(), truth, LAWS, strict=True):
        assert row["t_s"] == pytest.approx(true["t_s"], abs=0.5 / FPS)
        assert row["e_n"] == pytest.approx(e_n, abs=0.005)
        assert row["e_t"] == pytest.approx(e_t, abs=0.005)


def test_profile_gives_each_impact_its_own_slope(cli, scene, tmp_path, digest):
    before = digest(scene["profile"])
    table, result = _track(cli, scene, tmp_path, "--surface-profile", scene["profile"])
    _check_per_impact(table, scene["truth"], "profile")
    assert "dip of the segment of profile.csv (2 segments) nearest" in result.stderr
    assert "off contact with the surface profile" not in result.stderr
    assert digest(scene["profile"]) == before


def test_dem_plane_fit_gives_each_impact_its_own_slope(cli, scene, tmp_path):
    section = f"{E0_M},{N0_M},{E0_M + 1},{N0_M}"
    table, result = _track(
        cli, scene, tmp_path, "--surface-dem", scene["dem"], "--section", section
    )
    _check_per_impact(table, scene["truth"], "dem")
    # the footprint is stated: the body radius, at least one DEM cell
    assert "fitted within 0.05 m (the body radius, at least one DEM cell)" in (
        result.stderr
    )
    assert "over a disc of radius 0.05 m" in result.stderr
    assert "off contact" not in result.stderr  # the DEM is in the track's frame


def test_one_mean_slope_fails_the_same_check(cli, scene, tmp_path):
    """The independent demonstration: the same clip on one slope, 20 deg (the mean
    of the two segments), gives e_n off by 0.5 at both impacts."""
    mean = float(np.mean(DIPS_DEG))
    table, _ = _track(cli, scene, tmp_path, "--surface-angle", mean)
    assert len(table) == 2
    np.testing.assert_allclose(table["slope_deg"], [mean, mean])
    expected = [_true_restitution(t, mean) for t in scene["truth"]]
    errors = []
    for (_, row), exp, (e_n, e_t) in zip(table.iterrows(), expected, LAWS, strict=True):
        # the reduction itself is right: the mean slope's own decomposition of the
        # true velocities comes back ...
        assert row["e_n"] == pytest.approx(exp[0], abs=0.03)
        # ... and it is far from the truth on each segment's own slope
        errors.append((row["e_n"] - e_n, row["e_t"] - e_t))
    errors = np.array(errors)
    assert errors[0, 0] > 0.5 and errors[1, 0] < -0.4, errors
    assert np.abs(errors[:, 1]).min() > 0.07, errors


def test_misaligned_ground_is_warned_about(cli, scene, tmp_path):
    shifted = tmp_path / "shifted.csv"
    px, pz = profile_vertices()
    shifted.write_text(
        "x_m,z_m\n" + "\n".join(f"{x},{z - 0.3}" for x, z in zip(px, pz, strict=True))
    )
    _, result = _track(cli, scene, tmp_path, "--surface-profile", shifted)
    assert result.stderr.count("off contact with the surface profile") == 2
    dem = write_dem(tmp_path / "low.asc", offset_m=-0.3)
    section = f"{E0_M},{N0_M},{E0_M + 1},{N0_M}"
    table, result = _track(
        cli, scene, tmp_path, "--surface-dem", dem, "--section", section
    )
    assert result.stderr.count("off contact with the DEM's plane") == 2
    # the ground 0.3 m too low: the centre is 0.3 cos(psi) farther from its plane
    for point, psi in zip("12", DIPS_DEG, strict=True):
        gap = 0.3 * math.cos(math.radians(psi))
        assert f"impact {point}: the body's centre is {gap:+.3f} m off" in (
            result.stderr
        )
    np.testing.assert_allclose(table["slope_deg"], DIPS_DEG, atol=0.01)


@pytest.mark.parametrize(
    "args, words",
    [
        (("--surface-angle", "20", "--surface-profile", "P"), ("--surface-profile",)),
        (("--section", "0,0,1,0"), ("--section", "--surface-dem")),
        (("--surface-dem", "D"), ("--section", "needs")),
        (("--surface-dem", "D", "--section", "1,2,3"), ("--section", "E1,N1,E2,N2")),
        (("--surface-dem", "D", "--section", "1,2,1,2"), ("--section", "identical")),
        (
            ("--surface-dem", "D", "--section", "100,200,101,200", "--footprint", "-1"),
            ("--footprint", "> 0"),
        ),
    ],
)
def test_bad_ground_options_one_line_nothing_written(
    cli, scene, tmp_path, fails, args, words
):
    named = {"P": str(scene["profile"]), "D": str(scene["dem"])}
    args = [named.get(a, a) for a in args]
    out = tmp_path / "impacts.csv"
    fails(
        cli(
            "track", scene["video"], "--fps", FPS, "--homography", scene["homography"],
            "--radius", RADIUS_M, "--impacts", out, *args,
        ),
        *words,
    )  # fmt: skip
    assert not out.exists()


def test_contact_off_the_dem_one_error_nothing_written(cli, scene, tmp_path):
    """A section line off the DEM is found at the first contact (after tracking)."""
    out = tmp_path / "impacts.csv"
    result = cli(
        "track", scene["video"], "--fps", FPS, "--homography", scene["homography"],
        "--radius", RADIUS_M, "--impacts", out, "--surface-dem", scene["dem"],
        "--section", "1,2,3,4",
    )  # fmt: skip
    assert result.exit_code == 1
    errors = [line for line in result.stderr.splitlines() if line.startswith("error")]
    assert len(errors) == 1 and "Traceback" not in result.stderr
    assert "dem.asc" in errors[0] and "off the grid or nodata" in errors[0]
    assert not out.exists()


def test_track_body_from_block_dimensions(cli, scene, tmp_path):
    """The track's body from a block's principal lengths (`--shape block`): k of the
    solid ellipsoid rolling about its shortest axis reaches every impact row; the
    restitution on the known ground does not depend on it."""
    table, result = _track(
        cli, scene, tmp_path, "--surface-profile", scene["profile"],
        "--shape", "block", "--dimensions", "0.05,0.09,0.07",
    )  # fmt: skip
    k = math.sqrt((0.09**2 + 0.07**2) / 20.0)
    np.testing.assert_allclose(table["gyration_m"], k, rtol=1e-12)
    # --radius 0.0375 overrides the block's contact radius (0.045 + 0.035) / 2
    np.testing.assert_allclose(table["radius_m"], RADIUS_M)
    assert "note: --radius 0.0375 m overrides the block's contact radius 0.04 m" in (
        result.stderr
    )
    _check_per_impact(table, scene["truth"], "profile")


def test_travel_toward_minus_x_turns_the_profile_dip(cli, scene, render, tmp_path):
    """The same bounce mirrored (x -> 1 - x): the ball travels toward -x down a
    profile that rises toward +x; the table's x is mirrored, and each impact's slope
    is still 10 and 30 deg descending along travel."""
    poses, _ = bounce_on_profile()
    poses[:, 0] = 1.0 - poses[:, 0]
    poses[:, 2] = np.pi - poses[:, 2]
    video = _render_clip(render, tmp_path / "mirrored.avi", poses)
    px, pz = profile_vertices()
    profile = tmp_path / "mirrored.csv"
    profile.write_text(
        "x_m,z_m\n"
        + "\n".join(
            f"{1 - x:.9f},{z:.9f}" for x, z in zip(px[::-1], pz[::-1], strict=True)
        )
    )
    out = tmp_path / "impacts.csv"
    result = cli(
        "track", video, "--fps", FPS, "--homography", scene["homography"],
        "--radius", RADIUS_M, "--impacts", out, "--surface-profile", profile,
    )  # fmt: skip
    assert result.exit_code == 0, result.stderr
    assert "the body travels toward -x" in result.stderr
    assert "off contact" not in result.stderr
    _check_per_impact(pd.read_csv(out), scene["truth"], "profile")
