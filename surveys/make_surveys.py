"""Regenerate every file in ``surveys/`` from the thesis tables typed in below.

Run from the repository root::

    .venv/bin/python surveys/make_surveys.py

The output is deterministic (fixed site origin, azimuth, declination and a seeded
``numpy.random.Generator`` for where the reconstructed tree strikes sit), so running it
again reproduces the committed files byte for byte. Each folder's README says what the
thesis gives and what was reconstructed.

Sources (Wyllie, *Rock fall engineering*, thesis ch. 2):
Table 2-1 Mt. Stephen, Table 2-2 Kreuger Quarry, Table 2-3 Ehime, Table 2-4 Tornado
Mountain boulder A, Table 2-5 asphalt. Columns typed: point, x [m], z [m], alpha_f [deg]
(restitution angle measured counter-clockwise from an x axis pointing against travel,
so alpha = 180 - alpha_f), slope psi_s [deg], e_N, e_T, kinetic energy lost [J].
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np
import pyproj

HERE = Path(__file__).resolve().parent
G = 9.81
NAN = float("nan")

# --------------------------------------------------------------------------- tables
# point, x_m, z_m, alpha_f_deg, psi_deg, e_n, e_t, dke_j, material
TABLE_2_4 = """\
A 0.00 350.00 - - - - - rock
B 8.00 316.00 213.0 76.7 0.24 0.97 -597368 rock
C 28.00 295.00 205.0 46.4 0.98 0.74 -636093 rock
D 48.00 280.00 200.0 36.9 1.12 0.84 -383565 talus
E 72.00 265.00 185.0 32.0 1.19 0.74 -649674 talus
1 98.00 255.45 167.6 20.2 1.35 0.35 -968096 colluvium
2 117.70 244.60 176.2 28.8 0.78 0.53 -428292 colluvium
3 132.60 236.15 177.0 29.6 0.88 0.53 -346394 colluvium
4 144.60 229.50 176.4 29.0 1.11 0.60 -227818 colluvium
5 158.80 221.05 168.0 30.8 1.23 0.52 -291750 colluvium
6 176.60 210.90 177.1 29.7 0.82 0.60 -349399 colluvium
7 192.20 202.45 175.8 28.4 0.82 0.48 -396086 colluvium
8 202.40 197.10 175.1 27.7 1.29 0.72 -119311 colluvium
9 218.70 188.05 176.4 29.0 0.63 0.41 -458078 colluvium
10 225.70 184.40 174.9 27.5 1.50 0.79 -42725 colluvium
11 240.20 176.05 177.3 29.9 0.90 0.60 -294735 colluvium
12 253.30 169.30 174.7 27.3 1.26 0.68 -188389 colluvium
13 272.00 159.25 175.7 28.3 0.68 0.44 -498765 colluvium
14 281.20 154.60 174.2 26.8 1.10 0.62 -163044 colluvium
15 291.60 149.15 175.1 27.7 1.00 0.54 -218672 colluvium
16 301.70 143.10 178.3 30.9 0.99 0.62 -195226 colluvium
17 312.60 136.75 177.6 30.2 1.46 0.79 -80514 colluvium
18 335.00 123.10 178.8 31.4 0.85 0.48 -585150 colluvium
19 351.60 112.65 179.6 32.2 1.02 0.65 -312023 colluvium
20 370.40 102.20 194.5 29.1 0.59 0.85 -218275 colluvium
21 383.50 95.25 175.3 27.9 1.44 0.44 -542278 colluvium
22 395.60 89.00 189.0 27.3 0.72 0.60 -259761 colluvium
23 416.40 77.90 171.0 33.4 1.36 0.57 -200941 colluvium
24 427.20 72.65 173.3 25.9 0.94 0.65 -179329 colluvium
25 437.70 67.90 171.7 24.3 0.89 0.53 -224677 colluvium
26 445.60 64.25 142.6 24.8 1.29 0.27 -179883 colluvium
27 452.10 61.20 172.5 25.1 0.89 1.03 -6012 colluvium
28 463.00 56.55 158.0 23.1 1.03 0.42 -248912 colluvium
29 470.90 53.40 169.1 21.7 0.78 0.65 -117853 colluvium
30 477.40 50.75 166.0 22.2 1.24 0.75 -56926 colluvium
31 486.70 47.20 168.0 20.9 1.10 0.67 -114798 colluvium
32 497.80 42.15 171.9 24.5 1.00 0.69 -165182 colluvium
33 519.30 33.30 174.0 23.4 1.17 0.71 -190159 colluvium
34 531.90 28.75 167.3 19.9 0.89 0.48 -296884 colluvium
35 539.60 25.80 168.4 21.0 0.95 0.65 -116052 colluvium
36 546.70 23.05 145.0 21.2 1.21 0.32 -148602 colluvium
37 552.30 20.60 171.0 23.6 0.85 0.92 -29584 colluvium
38 560.20 17.25 170.4 23.0 0.90 0.55 -158313 colluvium
39 566.30 14.50 171.7 24.3 0.98 0.60 -106242 colluvium
40 572.20 11.65 173.2 25.8 0.98 0.76 -71215 colluvium
41 578.80 9.10 168.5 21.1 1.24 0.68 -87017 colluvium
42 587.20 5.55 171.8 22.9 1.30 1.22 135811 colluvium
43 605.80 0.00 164.0 16.6 0.57 0.73 -296779 bench
44 614.50 0.00 147.4 0.0 0.40 0.12 - bench
45 634.00 -4.00 - - - - - bench
"""

# Table 2-3, Ehime concrete cube (slope column = chord from the previous point).
TABLE_2_3 = """\
0 0.00 45.00 - - - - - rock
1 1.00 44.00 181.0 45.0 0.64 1.01 -1851 rock
2 3.00 42.50 205.0 36.9 0.89 0.95 -1263 rock
3 6.00 39.70 198.0 43.0 1.71 0.49 -17403 rock
4 12.00 31.75 209.7 53.0 0.34 0.94 -8303 rock
5 15.00 29.67 189.7 34.7 4.58 0.58 -30832 rock
6 28.00 18.23 209.1 41.3 0.22 0.73 -45806 talus
7 31.00 16.19 185.6 34.2 5.47 0.71 -17642 talus
8 49.00 2.57 184.5 37.1 0.00 0.00 -25873 talus
9 53.00 2.00 - - - - -148973 talus
"""

# Table 2-5, impact on asphalt (slopes are the surveyed ground, not chords).
TABLE_2_5 = """\
source 0.00 637.00 - - - - - rock
1 113.00 511.00 212.0 41.0 0.17 27.60 -570123 rock
2 124.00 501.00 118.0 0.0 0.38 0.24 -106024 asphalt
3 127.10 502.63 - - - - - asphalt
"""

# Table 2-2, Kreuger Quarry, 15 m cut at 76° with a horizontal ditch.
TABLE_2_2 = """\
crest 0.00 15.00 - 0.0 - - - rock
face 1.50 7.00 225.0 76.0 -2.51 0.59 -14248 rock
ditch 6.25 0.10 140.0 0.0 0.24 0.55 -56122 rock
second 9.00 0.00 - - - - - rock
"""

# Table 2-1, Mt. Stephen trajectory S-A-B.
TABLE_2_1 = """\
source 40.00 112.00 - - - - - rock
A 60.00 71.50 200.0 41.0 0.75 0.68 -10270 rock
barrier 117.00 8.00 - - - - - barrier
"""


def parse(table: str) -> list[dict]:
    """Rows of a typed table as dicts (``-`` becomes NaN)."""
    keys = (
        "point",
        "x_m",
        "z_m",
        "alpha_f_deg",
        "psi_deg",
        "e_n",
        "e_t",
        "dke_j",
        "material",
    )
    rows = []
    for line in table.strip().splitlines():
        cells = line.split()
        row = dict(zip(keys, cells, strict=True))
        for key in keys[1:-1]:
            row[key] = NAN if row[key] == "-" else float(row[key])
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- helpers
GEOD = pyproj.Geod(ellps="WGS84")

#: Plausible site: colluvium slope below Tornado Mountain, Crowsnest Pass area (the
#: thesis gives no coordinates). Path heads down-slope on a fixed azimuth.
TORNADO_ORIGIN = (49.9712, -114.6804)  # lat, lon of the source (point A)
TORNADO_AZIMUTH_DEG = 236.0  # true azimuth of travel
TORNADO_DATUM_M = 1352.0  # elevation of the thesis z = 0 (railway bench)
TORNADO_DECLINATION_DEG = 14.2  # magnetic declination east, set in the field book


def fmt(value: float, digits: int) -> str:
    return f"{value:.{digits}f}"


def csv_text(header: list[str], rows: list[list]) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return out.getvalue()


def gpx_text(name: str, description: str, waypoints: list[dict]) -> str:
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<gpx version="1.1" creator="fieldkit surveys/make_surveys.py"',
        '     xmlns="http://www.topografix.com/GPX/1/1">',
        "  <metadata>",
        f"    <name>{name}</name>",
        f"    <desc>{description}</desc>",
        "  </metadata>",
    ]
    for w in waypoints:
        lines.append(f'  <wpt lat="{w["lat"]:.9f}" lon="{w["lon"]:.9f}">')
        lines.append(f"    <ele>{w['ele']:.2f}</ele>")
        lines.append(f"    <name>{w['name']}</name>")
        if w.get("desc"):
            lines.append(f"    <desc>{w['desc']}</desc>")
        if w.get("type"):
            lines.append(f"    <type>{w['type']}</type>")
        lines.append("  </wpt>")
    lines.append("</gpx>")
    return "\n".join(lines) + "\n"


def chord_slope_deg(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Dip of the chord from the previous point (NaN for the first)."""
    psi = np.full(len(x), NAN)
    psi[1:] = np.degrees(np.arctan2(-(z[1:] - z[:-1]), x[1:] - x[:-1]))
    return psi


def parabola_height(dx: float, dz: float, alpha_deg: float, d: float) -> float:
    """Height above the chord at ``d`` of the eq. 3.5 parabola launched at ``alpha``."""
    a = math.radians(alpha_deg)
    v0 = dx / (math.cos(a) * math.sqrt(2.0 * (dx * math.tan(a) - dz) / G))
    z = d * math.tan(a) - G * d**2 / (2.0 * (v0 * math.cos(a)) ** 2)
    return z - d * dz / dx


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path.relative_to(HERE.parent)}")


# --------------------------------------------------------------------------- Tornado
def tornado_positions(rows: list[dict]) -> list[tuple[float, float]]:
    """Lat/lon of each point: geodesic steps of dx on a fixed azimuth from origin."""
    lat, lon = TORNADO_ORIGIN
    out = [(lat, lon)]
    for prev, row in zip(rows[:-1], rows[1:], strict=True):
        lon, lat, _ = GEOD.fwd(lon, lat, TORNADO_AZIMUTH_DEG, row["x_m"] - prev["x_m"])
        out.append((lat, lon))
    return out


def tornado_trees(rows: list[dict], rng: np.random.Generator) -> list[list]:
    """One tree strike on each flight whose printed alpha_f gives theta0 != 32.6°.

    The strike sits on the thesis's own parabola (eq. 3.5 with that flight's alpha) at
    random 35-65 % of the flight, distance rounded to 0.1 m (tape) and height to 0.01 m.
    """
    x = np.array([r["x_m"] for r in rows])
    z = np.array([r["z_m"] for r in rows])
    psi = chord_slope_deg(x, z)
    species = ("lodgepole pine", "Douglas-fir", "lodgepole pine", "trembling aspen")
    out = []
    for j in range(len(rows) - 1):
        alpha = 180.0 - rows[j]["alpha_f_deg"]
        theta0 = alpha + psi[j]
        if not np.isfinite(theta0) or abs(theta0 - 32.6) < 0.1:
            continue
        dx, dz = x[j + 1] - x[j], z[j + 1] - z[j]
        d = round(float(rng.uniform(0.35, 0.65)) * dx, 1)
        h = parabola_height(dx, dz, alpha, d)
        kind = species[int(rng.integers(len(species)))]
        dbh = int(round(float(rng.uniform(160, 300)), -1))
        out.append([rows[j]["point"], fmt(d, 1), fmt(h, 2), kind, dbh])
    return out


def tornado(rows: list[dict]) -> None:
    folder = HERE / "tornado_mountain"
    positions = tornado_positions(rows)
    waypoints = [
        {
            "lat": lat,
            "lon": lon,
            "ele": r["z_m"] + TORNADO_DATUM_M,
            "name": r["point"],
            "type": r["material"],
            "desc": "source" if i == 0 else ("stopped" if i == len(rows) - 1 else ""),
        }
        for i, (r, (lat, lon)) in enumerate(zip(rows, positions, strict=True))
    ]
    write(
        folder / "boulder_a_impacts.gpx",
        gpx_text(
            "Tornado Mountain boulder A impacts",
            "Thesis Table 2-4 x,z placed on a plausible site; elevation = z + "
            f"{TORNADO_DATUM_M:.1f} m; WGS 84 ellipsoidal positions, heights as given.",
            waypoints,
        ),
    )
    rng = np.random.default_rng(2004)
    trees = tornado_trees(rows, rng)
    write(
        folder / "boulder_a_trees.csv",
        csv_text(
            [
                "after_impact",
                "horizontal_distance_m",
                "strike_height_m",
                "species",
                "dbh_mm",
            ],
            trees,
        ),
    )
    write(
        folder / "boulder_a_section.csv",
        csv_text(
            ["point", "x_m", "z_m", "material"],
            [
                [r["point"], fmt(r["x_m"], 2), fmt(r["z_m"], 2), r["material"]]
                for r in rows
            ],
        ),
    )
    write(folder / "table_2_4_thesis.csv", thesis_csv(rows))
    rangefinder(rows, positions, folder)


def rangefinder(rows: list[dict], positions: list, folder: Path) -> None:
    """GPS stations beside the path and TruPulse HV shots to every impact."""
    from fieldkit.io.trupulse import format_trupulse_hv

    x = np.array([r["x_m"] for r in rows])
    z = np.array([r["z_m"] for r in rows])
    lat0, lon0 = TORNADO_ORIGIN
    # Stations every ~55 m along the path, 7 m to alternate sides, on the ground.
    station_x = [
        14.0,
        60.0,
        110.0,
        165.0,
        220.0,
        275.0,
        330.0,
        385.0,
        440.0,
        495.0,
        550.0,
        600.0,
    ]
    stations = []
    for k, sx in enumerate(station_x):
        lon, lat, _ = GEOD.fwd(lon0, lat0, TORNADO_AZIMUTH_DEG, sx)
        side = 90.0 if k % 2 == 0 else -90.0
        lon, lat, _ = GEOD.fwd(lon, lat, TORNADO_AZIMUTH_DEG + side, 7.0)
        ground = float(np.interp(sx, x, z)) + TORNADO_DATUM_M
        stations.append(
            {
                "name": f"S{k + 1}",
                "lat": round(lat, 9),
                "lon": round(lon, 9),
                "ele": round(ground, 2),
                "x": sx,
                "desc": "GPS station",
            }
        )
    write(
        folder / "boulder_a_stations.gpx",
        gpx_text(
            "Tornado Mountain boulder A rangefinder stations",
            "GNSS-fixed instrument stations; elevation on the impacts' datum.",
            stations,
        ),
    )
    book = []
    for i, (row, (lat, lon)) in enumerate(zip(rows, positions, strict=True)):
        st = min(stations, key=lambda s: abs(s["x"] - row["x_m"]))
        az_fwd, _, hd = GEOD.inv(st["lon"], st["lat"], lon, lat)
        instrument_h = 1.60
        # Reflectorless shots to scars on the cliff (A, B); a target pole elsewhere.
        target_h = 0.0 if i < 2 else (1.80 if i % 7 == 3 else 1.50)
        dz = (row["z_m"] + TORNADO_DATUM_M + target_h) - (st["ele"] + instrument_h)
        inc = math.degrees(math.atan2(dz, hd))
        sd = math.hypot(hd, dz)
        az_mag = (az_fwd - TORNADO_DECLINATION_DEG) % 360.0
        sentence = format_trupulse_hv(
            round(hd, 1), round(az_mag, 1), round(inc, 1), round(sd, 1), units="M"
        )
        book.append(
            [
                row["point"],
                st["name"],
                fmt(instrument_h, 2),
                fmt(target_h, 2),
                "magnetic",  # the TruPulse 360's own declination left at 0
                sentence,
            ]
        )
    write(
        folder / "boulder_a_fieldbook.csv",
        csv_text(
            [
                "point",
                "station",
                "instrument_height_m",
                "target_height_m",
                "azimuth_reference",
                "sentence",
            ],
            book,
        ),
    )


def thesis_csv(rows: list[dict]) -> str:
    """The typed thesis table itself, for reference (not an input format)."""

    def cell(v: float, d: int) -> str:
        return "" if not np.isfinite(v) else fmt(v, d)

    return csv_text(
        [
            "point",
            "x_m",
            "z_m",
            "alpha_f_deg",
            "slope_deg",
            "e_n",
            "e_t",
            "dke_j",
            "material",
        ],
        [
            [
                r["point"],
                cell(r["x_m"], 2),
                cell(r["z_m"], 2),
                cell(r["alpha_f_deg"], 1),
                cell(r["psi_deg"], 1),
                cell(r["e_n"], 2),
                cell(r["e_t"], 2),
                cell(r["dke_j"], 0),
                r["material"],
            ]
            for r in rows
        ],
    )


# --------------------------------------------------------------------------- others
def section_with_angles(
    rows: list[dict], *, surveyed_slope: bool, ft: bool = False
) -> str:
    """Section CSV: x, z, material, surveyed slope (optional) and given theta0.

    ``theta0_deg`` is the thesis's restitution angle to the ground for the flight that
    leaves the point, theta0 = alpha + psi with alpha = 180 - alpha_f (eq. 3.6).
    """
    x = np.array([r["x_m"] for r in rows])
    z = np.array([r["z_m"] for r in rows])
    chord = chord_slope_deg(x, z)
    unit = "ft" if ft else "m"
    scale = 1.0 / 0.3048 if ft else 1.0
    header = ["point", f"x_{unit}", f"z_{unit}", "material"]
    if surveyed_slope:
        header.append("slope_deg")
    header.append("theta0_deg")
    out = []
    for i, r in enumerate(rows):
        psi = r["psi_deg"] if surveyed_slope else chord[i]
        theta0 = 180.0 - r["alpha_f_deg"] + psi
        line = [
            r["point"],
            fmt(r["x_m"] * scale, 3 if ft else 2),
            fmt(r["z_m"] * scale, 3 if ft else 2),
            r["material"],
        ]
        if surveyed_slope:
            line.append("" if not np.isfinite(r["psi_deg"]) else fmt(r["psi_deg"], 1))
        line.append("" if not np.isfinite(theta0) else fmt(theta0, 2))
        out.append(line)
    return csv_text(header, out)


def main() -> None:
    tornado(parse(TABLE_2_4))
    ehime = parse(TABLE_2_3)
    write(
        HERE / "ehime" / "cube_section.csv",
        section_with_angles(ehime, surveyed_slope=False),
    )
    write(HERE / "ehime" / "table_2_3_thesis.csv", thesis_csv(ehime))
    asphalt = parse(TABLE_2_5)
    write(
        HERE / "asphalt" / "asphalt_section.csv",
        section_with_angles(asphalt, surveyed_slope=True),
    )
    write(HERE / "asphalt" / "table_2_5_thesis.csv", thesis_csv(asphalt))
    kreuger = parse(TABLE_2_2)
    write(
        HERE / "kreuger_quarry" / "kreuger_section_ft.csv",
        section_with_angles(kreuger, surveyed_slope=True, ft=True),
    )
    write(HERE / "kreuger_quarry" / "table_2_2_thesis.csv", thesis_csv(kreuger))
    stephen = parse(TABLE_2_1)
    write(
        HERE / "mt_stephen" / "stephen_section.csv",
        section_with_angles(stephen, surveyed_slope=True),
    )
    write(HERE / "mt_stephen" / "table_2_1_thesis.csv", thesis_csv(stephen))


if __name__ == "__main__":
    main()
