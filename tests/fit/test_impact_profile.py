"""Issue 20 (H4): profile-likelihood intervals of the impact fit (through the CLI)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

TORNADO = Path(__file__).parents[2] / "surveys" / "tornado_mountain"
TABLE_7_1 = TORNADO / "model_rocfall_table_7_1.json"
K = "velocity_scaled_restitution.k_mps"


def _fit(cli, tmp_path, table, model, name):
    out = tmp_path / f"{name}.json"
    r = cli("fit", table, "--model", model, "-o", out, "--report", tmp_path / name)
    assert r.exit_code == 0, r.output
    return r, json.loads(out.read_text())["provenance"]["fit"]


def test_linear_problem_profile_equals_jacobian_interval(cli, tmp_path):
    """Table 7-1's laws are linear in e_n and e_t: the profile interval and value ± t
    SE (t of the residual degrees of freedom) agree to the ends' tolerance; three
    paths: no one-path statement."""
    table = tmp_path / "s.csv"
    r = cli("synth", TABLE_7_1, "--paths", "3", "--seed", "4", "--noise", "0.1",
            "-o", table)  # fmt: skip
    assert r.exit_code == 0, r.output
    r, fit = _fit(cli, tmp_path, table, TABLE_7_1, "lin")
    prof = fit["profile"]
    assert prof["dof"] == fit["n_data"] - len(fit["parameters"])
    assert prof["threshold"] == pytest.approx(prof["t_quantile"] ** 2)
    assert len(prof["parameters"]) == 4
    for q in prof["parameters"]:
        se = fit["parameters"][q["name"]]["stderr"]
        half = prof["t_quantile"] * se
        assert q["jacobian90"] == pytest.approx([q["value"] - half, q["value"] + half])
        assert q["interval90"] == pytest.approx(q["jacobian90"], abs=2e-3 * half)
        assert q["asymmetry"] == pytest.approx(1.0, abs=0.01)
        assert q["open"] == [False, False]
    assert prof["one_path"] is None and "one path:" not in r.stdout
    assert "90 % intervals: profile likelihood" in r.stdout
    report = (tmp_path / "lin" / "report.md").read_text()
    assert "## Profile-likelihood intervals" in report and "Lower bounds" not in report


def test_nonlinear_velocity_scale_profile_is_longer_above(cli, tmp_path):
    """eq. 7.1's velocity scale K: its effect fades as K grows, so the sum of squares
    rises slowly above the fit and fast below: the profile interval lies above the
    Jacobian's at both ends and its upper half is the longer (known truth K = 8 inside
    it); one path: the lower-bound statement is printed with the intervals."""
    table = tmp_path / "s.csv"
    hidden = "velocity_scaled_restitution=k_mps=8"
    r = cli("synth", TABLE_7_1, "--paths", "1", "--seed", "2", "--noise", "0.1",
            "--effects", hidden, "-o", table)  # fmt: skip
    assert r.exit_code == 0, r.output
    model = json.loads(TABLE_7_1.read_text())
    model["effects"]["velocity_scaled_restitution"] = {"k_mps": 9.144}
    base = tmp_path / "vsr.json"
    base.write_text(json.dumps(model))
    r, fit = _fit(cli, tmp_path, table, base, "nonlin")
    (q,) = [q for q in fit["profile"]["parameters"] if q["name"] == K]
    (lo, hi), (jlo, jhi) = q["interval90"], q["jacobian90"]
    assert lo <= 8.0 <= hi
    assert lo > jlo + 0.5 and hi > jhi + 2.0
    assert q["asymmetry"] > 2.0 and q["open"] == [False, False]
    out = r.stdout.splitlines()
    at = next(i for i, x in enumerate(out) if x.startswith("90 % intervals: profile"))
    assert out[at - 1].startswith("one path: its impacts are not independent")
    assert "another boulder, another path" in out[at - 1]
    assert any(x.strip().startswith(f"{K}  profile {lo:.4g} to {hi:.4g}")
               for x in out)  # fmt: skip
    report = (tmp_path / "nonlin" / "report.md").read_text()
    assert "**Lower bounds.** One path: its impacts are not independent" in report
