"""The keys and distribution ids of RocFall's material and rock-type blocks, as
fieldkit writes them (:mod:`fieldkit.export.rocfall`) and reads them back
(:mod:`fieldkit.export.rocfall_import`)."""

from __future__ import annotations

#: RocFall distribution ids (the issue's list; RocFall3 help "Random Variables").
DISTRIBUTIONS: dict[int, str] = {
    1: "none",
    2: "normal",
    3: "uniform",
    4: "triangular",
    5: "beta",
    6: "exponential",
    7: "lognormal",
    8: "gamma",
}
#: Material keys -> (fieldkit field, unit written in the key).
MATERIAL_KEYS: dict[str, tuple[str, str]] = {
    "rn": ("e_n", ""),
    "rt": ("e_t", ""),
    "friction angle": ("friction_deg", "deg"),
    "slope roughness sd": ("roughness_deg_sd", "deg"),
}
#: Rock-type keys -> (fieldkit seeder/body field, SD field, unit).
ROCK_KEYS: dict[str, tuple[str, str, str]] = {
    "mass": ("mass_kg", "mass_sd_kg", "kg"),
    "initial horizontal velocity": ("vx_mps", "vx_sd_mps", "m/s"),
    "initial vertical velocity": ("vz_mps", "vz_sd_mps", "m/s"),
    "initial rotational velocity": ("omega_radps", "omega_sd_radps", "rad/s"),
}
