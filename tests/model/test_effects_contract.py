"""One contract over the registry: every effect obeys the same rules."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest
from model_builders import build, same_result

from fieldkit.errors import ArgumentError, InputFileError
from fieldkit.model import simulate
from fieldkit.model.effects.registry import BY_NAME, EFFECTS, describe, effect
from fieldkit.model.effects.spec import EXPORT_TARGETS, NORMAL_REBOUND, REBOUND, Export

NAMES = [spec.name for spec in EFFECTS]
CONTRACT = {
    "angle_dependent_restitution", "velocity_scaled_restitution", "rotation_friction",
    "slope_roughness", "mass_loss", "tree_impacts", "air_drag",
}  # fmt: skip
#: Statistical alternatives the diagnosis compares the laws with (issue 18).
ALTERNATIVES = {"affine_rebound"}


def test_registry_is_the_architecture_vocabulary():
    assert set(NAMES) == CONTRACT | ALTERNATIVES
    assert len(NAMES) == len(CONTRACT) + len(ALTERNATIVES)
    assert {s.name for s in EFFECTS if s.is_law} == CONTRACT
    assert {s.name for s in EFFECTS if not s.is_law} == ALTERNATIVES


@pytest.mark.parametrize("name", NAMES)
def test_metadata_is_complete_and_defaults_in_bounds(name):
    spec = effect(name)
    assert spec.stage in ("impact", "flight", "slide")
    assert spec.summary and spec.physics and spec.reference
    assert spec.parameters
    for p in spec.parameters:
        assert p.lower <= p.default <= p.upper, p.name
        assert p.units and p.description
        if p.neutral is not None:
            assert p.lower <= p.neutral <= p.upper
    assert any(p.neutral is not None for p in spec.parameters)
    text = describe(name)
    for p in spec.parameters:
        assert f"{name}.{p.name}" in text


@pytest.mark.parametrize("name", NAMES)
def test_metadata_answers_what_consumers_ask(name):
    """Rebound, ImpactTable, export: every consumer reads these (issue 21)."""
    spec = effect(name)
    # changes_rebound is exactly "writes a part of the rebound"; the normal part
    # is what a target with another normal law cannot take
    assert spec.changes_rebound == bool(set(spec.writes) & set(REBOUND)), name
    assert spec.changes_normal_rebound == bool(set(spec.writes) & set(NORMAL_REBOUND))
    assert spec.changes_rebound <= (spec.stage == "impact")
    # a flight-stage effect leaves no mark on one impact: it must say why
    assert bool(spec.not_from_impacts) >= (spec.stage != "impact")
    # every law says how each lumped target takes it; the alternative none
    if spec.is_law:
        assert set(spec.exports) == set(EXPORT_TARGETS), name
        for target in EXPORT_TARGETS:
            rule = spec.export(target)
            assert isinstance(rule, Export) and rule.how, (name, target)
    else:
        assert dict(spec.exports) == {}
    for p in spec.parameters:
        assert isinstance(p.held, str)
    text = describe(name)
    for target in EXPORT_TARGETS:
        assert f"export to {target}: " in text
    held = [p.held for p in spec.parameters if p.held]
    assert text.count("held by an impact fit: ") == len(held)
    for why in held:
        assert f"held by an impact fit: {why}" in text


def test_3d_targets_read_the_metadata():
    """RAMMS, Rockyfor3D and r.stone keep no list of effects of their own: r.stone's
    effect lines are the metadata's words (the random dip adds that its rebounds are
    in the fitted pair)."""
    from fieldkit.export import ramms, rockyfor3d, rstone

    for module in (ramms, rockyfor3d, rstone):
        assert not hasattr(module, "EFFECT_REASONS")
        assert not hasattr(module, "NO_PROCESS")
    lines = dict(rstone.effect_lines(build()))
    for spec in EFFECTS:
        why = lines[f"effect {spec.name} (not in the model)"]
        if spec.is_law:
            assert why.startswith(spec.export("r.stone").how), spec.name
        else:
            assert "statistical alternative" in why


def test_consumers_read_the_metadata():
    from fieldkit.diagnose.candidates import IMPACT_CANDIDATES
    from fieldkit.export import crsp, lumped, rocfall
    from fieldkit.fit.impact_fit import HELD

    assert set(IMPACT_CANDIDATES) == {s.name for s in EFFECTS if not s.not_from_impacts}
    rebound = {s.name for s in EFFECTS if s.changes_rebound}
    assert set(lumped.RESTITUTION_LAWS) == rebound
    for module, target in ((crsp, "CRSP"), (rocfall, "RocFall")):
        assert module.EFFECT_RULES == {
            s.name: (s.exports[target].mapped, s.exports[target].how)
            for s in EFFECTS
            if s.is_law
        }
    assert HELD == {
        f"{s.name}.{p.name}": p.held for s in EFFECTS for p in s.parameters if p.held
    }
    assert set(HELD) == {
        "angle_dependent_restitution.theta_ref_deg",
        "angle_dependent_restitution.a",
        "slope_roughness.scale",
    }


@pytest.mark.parametrize("name", NAMES)
def test_neutral_parameters_reproduce_the_base_model_exactly(name):
    rng_args = dict(record_impacts=True, analysis_x_m=[50.0])
    base = simulate(build(sd=True), 300, np.random.default_rng(11), **rng_args)
    # the neutral values go to the simulator directly: a neutral value may be
    # infinite (velocity_scaled_restitution's K), which no model file may hold
    # (non-finite numbers are refused there; an effect is off by leaving it out)
    neutral = replace(
        build({name: {}}, sd=True), effects={name: effect(name).neutral()}
    )
    other = simulate(neutral, 300, np.random.default_rng(11), **rng_args)
    assert same_result(base, other)
    assert np.array_equal(
        base.analysis[0].speed_mps, other.analysis[0].speed_mps, equal_nan=True
    )


@pytest.mark.parametrize("name", NAMES)
def test_default_parameters_change_the_result(name):
    base = simulate(build(sd=True), 300, np.random.default_rng(11), record_impacts=True)
    on = simulate(
        build({name: {}}, sd=True), 300, np.random.default_rng(11), record_impacts=True
    )
    assert not same_result(base, on)


@pytest.mark.parametrize("name", NAMES)
def test_same_generator_same_result(name):
    model = build({name: {}}, sd=True)
    a = simulate(model, 200, np.random.default_rng(5), record_impacts=True)
    b = simulate(model, 200, np.random.default_rng(5), record_impacts=True)
    c = simulate(model, 200, np.random.default_rng(6), record_impacts=True)
    assert same_result(a, b)
    assert not same_result(a, c)


def test_unknown_effect_lists_the_known_ones():
    with pytest.raises(ArgumentError) as err:
        effect("air_dragg")
    for name in NAMES:
        assert name in str(err.value)
    with pytest.raises(InputFileError) as err:
        build({"gravity_off": {}})
    assert str(err.value).startswith("test.json: effects.gravity_off: unknown effect")
    assert "rotation_friction" in str(err.value)


@pytest.mark.parametrize("name", NAMES)
def test_parameter_outside_bounds_is_one_line_naming_file_and_parameter(name):
    p = BY_NAME[name].parameters[0]
    bad = p.upper * 2 + 1 if math.isfinite(p.upper) else p.lower - 1
    with pytest.raises(InputFileError) as err:
        build({name: {p.name: bad}})
    text = str(err.value)
    assert text.startswith(f"test.json: effects.{name}.{p.name}: must be in [")
    assert "\n" not in text


def test_result_does_not_depend_on_threads_or_chunks():
    import numba
    from model_builders import ALL_EFFECTS

    model = build(ALL_EFFECTS, sd=True)
    a = simulate(model, 300, np.random.default_rng(2), record_impacts=True)
    chunks = []
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        b = simulate(
            model,
            300,
            np.random.default_rng(2),
            record_impacts=True,
            impact_chunk_rocks=70,
            on_impact_chunk=chunks.append,
        )
    finally:
        numba.set_num_threads(threads)
    assert len(chunks) == 5 and b.impact_table is None
    assert sum(len(c) for c in chunks) == a.impacts == b.impacts
    assert np.array_equal(a.runout_x_m, b.runout_x_m)
    assert np.array_equal(a.state, b.state)
    streamed = pd.concat([c.frame for c in chunks], ignore_index=True)
    cols = ["path_id", "point", "x_m", "vf_x_mps", "omega_f_radps", "mass_kg"]
    pd.testing.assert_frame_equal(streamed[cols], a.impact_table.frame[cols])
    assert chunks[1].frame["path_id"].iloc[0] == "70"
