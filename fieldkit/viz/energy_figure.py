"""Energy along a reduced path (thesis §6.4).

* :func:`plot_energy_partition` -- Fig. 6.5: at each elevation of the fall, the energy
  split into potential (PE = m g (z - z_stop), eq. 6.13), translational kinetic (KE)
  and rotational (RE) energy, stacked left to right; what is left of the source's PE
  is the cumulative loss on impacts. KE rises along each flight and drops at each
  impact; RE is constant in flight.
* :func:`plot_energy_head` -- §6.4.2: the energy head ``E = z + v^2/(2g)`` (eq. 6.14),
  level during each flight and dropping at each impact, above the ground profile.

Legends sit outside the axes; impacts with quality flags (``qa_flags``) are ringed in
red.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from fieldkit.impact_table import ImpactTable
from fieldkit.outputs import OutputSet
from fieldkit.physics.energy import energy_head, kinetic_energy, potential_energy
from fieldkit.physics.flight import flight_samples
from fieldkit.viz.figure_files import save_png
from fieldkit.viz.marks import impact_rows, mark_flagged, outside_legend, qa_column


def energy_profile(table: ImpactTable, n_samples: int = 30) -> dict[str, np.ndarray]:
    """Energies sampled along the path (first path of the table) [J, m].

    Returns ``z_m``, ``x_m``, ``pe_j``, ``ke_j``, ``re_j`` and ``head_m``, with each
    flight sampled in time and each impact as two samples at the same point (before
    and after).
    """
    f = table.frame[table.frame["path_id"] == table.paths()[0]]
    m = float(f["mass_kg"].iloc[0])
    z_stop = float(f["z_m"].iloc[-1])
    xs, zs, speeds, res = [], [], [], []
    for row in f.itertuples(index=False):
        if np.isfinite(row.vi_mps):  # the impact itself: before, then after
            xs.append(row.x_m)
            zs.append(row.z_m)
            speeds.append(row.vi_mps)
            res.append(row.re_i_j)
        if not np.isfinite(row.flight_time_s):
            continue
        s = flight_samples(
            row.x_m, row.z_m, row.vf_x_mps, row.vf_z_mps, row.flight_time_s, n_samples
        )
        xs.extend(s.x_m)
        zs.extend(s.z_m)
        speeds.extend(s.speed_mps)
        res.extend(np.full(n_samples, row.re_f_j))
    x, z, v = np.asarray(xs), np.asarray(zs), np.asarray(speeds)
    return {
        "x_m": x,
        "z_m": z,
        "pe_j": potential_energy(m, z - z_stop),
        "ke_j": kinetic_energy(m, v),
        "re_j": np.nan_to_num(np.asarray(res)),
        "head_m": energy_head(z, v),
    }


def plot_energy_partition(table: ImpactTable) -> Figure:
    """Energy partition diagram (thesis Fig. 6.5); energies in kJ."""
    p = energy_profile(table)
    f = table.frame
    fig = Figure(figsize=(8.0, 7.0), layout="constrained")
    ax = fig.add_subplot()
    if not np.isfinite(p["pe_j"]).any():
        ax.text(
            0.5,
            0.5,
            "no mass given:\nno energies to partition",
            ha="center",
            va="center",
            transform=ax.transAxes,
        )
        ax.set_axis_off()
        return fig
    z = p["z_m"]
    pe, ke, re = p["pe_j"] / 1e3, p["ke_j"] / 1e3, p["re_j"] / 1e3
    total = float(pe[0] + ke[0] + re[0])
    ax.fill_betweenx(z, 0, pe, color="#9ecae1", label="potential energy PE", lw=0)
    ax.fill_betweenx(z, pe, pe + ke, color="#fdae6b", label="kinetic energy KE", lw=0)
    ax.fill_betweenx(
        z, pe + ke, pe + ke + re, color="#a1d99b", label="rotational energy RE", lw=0
    )
    ax.fill_betweenx(
        z,
        pe + ke + re,
        total,
        color="#e0e0e0",
        hatch="///",
        edgecolor="#9e9e9e",
        label="lost on impacts (cumulative)",
        lw=0,
    )
    ax.plot(pe + ke + re, z, color="black", lw=0.6)
    impacts = f[np.isfinite(f["dke_j"].to_numpy(float))]
    step = max(1, len(impacts) // 12)
    for k, row in enumerate(impacts.itertuples(index=False)):
        ax.axhline(
            row.z_m,
            color="0.6",
            lw=0.3,
            label="impact elevation (some labelled with the point)" if k == 0 else None,
        )
        if k % step == 0:
            ax.text(
                total * 1.025,
                row.z_m,
                str(row.point),
                fontsize=7,
                ha="center",
                va="center",
            )
    ax.set_xlim(0, total * 1.06)
    ax.set_ylim(z.min(), z.max())
    ax.set_xlabel("energy [kJ]")
    ax.set_ylabel("elevation [m]")
    ax.set_title(
        f"{table.paths()[0]}: energy partition (thesis Fig. 6.5), "
        f"m = {f['mass_kg'].iloc[0]:.0f} kg"
    )
    # ring the impact rows at the right edge, around their labels
    mark_flagged(
        ax, np.full(len(impacts), total * 1.025), impacts["z_m"], qa_column(impacts)
    )
    outside_legend(ax)
    return fig


def plot_energy_head(table: ImpactTable) -> Figure:
    """Energy head line over the ground profile (thesis §6.4.2, eq. 6.14)."""
    p = energy_profile(table)
    f = table.frame[table.frame["path_id"] == table.paths()[0]]
    fig = Figure(figsize=(10.0, 5.5), layout="constrained")
    ax = fig.add_subplot()
    x, z = f["x_m"].to_numpy(float), f["z_m"].to_numpy(float)
    ax.fill_between(x, z, z.min() - 5, color="#d9c7a7", alpha=0.6, lw=0)
    ax.plot(x, z, color="#6b4f2a", lw=1.0, label="ground (impact points)")
    ax.plot(
        p["x_m"],
        p["head_m"],
        color="#c62828",
        lw=1.3,
        label=r"energy head $E = z + v^2/2g$ (eq. 6.14)",
    )
    ax.plot(p["x_m"], p["z_m"], color="#1f4e9c", lw=0.7, ls="--", label="flight paths")
    head_i = f["energy_head_i_m"].to_numpy(float)
    ax.plot(
        x,
        head_i,
        "v",
        color="#c62828",
        ms=3.5,
        label="energy head just before an impact",
    )
    impacts = impact_rows(f)  # the release and stop points carry no impact flags
    mark_flagged(ax, x[impacts], head_i[impacts], qa_column(f[impacts]))
    ax.set_xlabel("x, horizontal distance along the path [m]")
    ax.set_ylabel("elevation / energy head [m]")
    ax.set_title(f"{table.paths()[0]}: energy head line (thesis §6.4.2)")
    ax.grid(True, alpha=0.3)
    outside_legend(ax)
    return fig


def write_energy_figures(
    table: ImpactTable,
    partition_path: str | os.PathLike[str],
    head_path: str | os.PathLike[str],
    *,
    outputs: OutputSet | None = None,
) -> tuple[Path, Path]:
    """Write the energy partition and energy head PNGs (into ``outputs`` if given).

    Without a mass the partition diagram has no energies; the energy head needs none.
    """
    return (
        save_png(plot_energy_partition(table), partition_path, outputs=outputs),
        save_png(plot_energy_head(table), head_path, outputs=outputs),
    )
