"""The import graph of the package follows the layering of docs/architecture.md §6.

Layers, lowest first (a module may import its own layer's package and any lower layer):

0. ``errors`` -- the one error type; ``_version`` -- the version string;
1. ``physics`` (pure thesis equations: imports nothing of ours but ``errors``) and
   ``outputs`` (safe file writing: all or nothing, never over an input);
2. the data types ``survey``, ``track``, ``impact_table``, ``path_observations``,
   ``measured`` (the ImpactTable's derived columns are thesis equations, so it
   imports ``physics``);
3. ``io`` -- field formats in, data types out; ``parallel`` -- the Dask engine that
   runs a stage's independent units (it imports no stage: the stages hand it
   functions and units);
4. the stages ``reduce``, ``tracking``, ``model``, ``fit``, ``diagnose``, ``export``,
   ``corridor``;
   a stage imports another stage only along :data:`STAGE_EDGES`;
5. ``viz`` -- figures and recordings of results;
6. ``cli`` -- the command line;
7. the package root (``fieldkit/__init__.py``, ``__main__``).

Every import counts, also one inside a function: an import moved into a function
hides a cycle from Python but not from this test.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "fieldkit"

LAYERS: dict[str, int] = {
    "_version": 0,
    "errors": 0,
    "physics": 1,
    "outputs": 1,
    "survey": 2,
    "track": 2,
    "impact_table": 2,
    "path_observations": 2,
    "measured": 2,
    "io": 3,
    "parallel": 3,
    "reduce": 4,
    "tracking": 4,
    "model": 4,
    "fit": 4,
    "diagnose": 4,
    "campaign": 4,
    "export": 4,
    "corridor": 4,
    "viz": 5,
    "cli": 6,
    "": 7,
    "__main__": 7,
}

#: Allowed imports between different stage packages (importer, imported). Sub-stages
#: are named with a dot: ``tracking.video`` and ``tracking.flights`` are independent.
STAGE_EDGES: frozenset[tuple[str, str]] = frozenset(
    {
        ("fit", "model"),
        ("diagnose", "model"),
        ("diagnose", "fit"),
        ("diagnose", "campaign"),
        ("diagnose", "reduce"),
        ("campaign", "model"),
        ("export", "model"),
        ("export", "fit"),
        # a corridor scan cuts sections and runs the 2-D and 3-D simulators
        ("corridor", "model"),
        # tracking.trajectory3d reads the ground as the 3-D model does (Terrain),
        # writes the 3-D simulator's impact rows (results3d.impact_table3d) and
        # samples its synthetic runs from the 3-D simulator
        # the flight segmentation tells mid-air misfits from contacts with the
        # simulator's own drag law (model.drag_flight, model.effects.air_drag)
        ("tracking", "model"),
    }
)


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def imports_of(path: Path) -> set[str]:
    """Every ``fieldkit`` module a file imports, at any depth of its code."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("fieldkit")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("fieldkit"):
                continue
            found.add(target)
            found |= {f"{target}.{a.name}" for a in node.names}
    return found


MODULES = {module_name(p): p for p in PACKAGE.rglob("*.py")}


def resolve(target: str) -> str | None:
    """The module a dotted import target names (``from pkg import mod`` or a name)."""
    while target and target not in MODULES:
        target = target.rpartition(".")[0]
    return target or None


def unit(module: str) -> str:
    """Top-level unit of a module: ``fieldkit.io.gpx`` -> ``io``; sub-stages of
    ``tracking`` keep their second name (``tracking.video``)."""
    parts = module.split(".")[1:]
    if not parts:
        return ""
    if parts[0] == "tracking" and len(parts) > 1 and parts[1] in ("video", "flights"):
        return f"tracking.{parts[1]}"
    return parts[0]


def layer(unit_name: str) -> int:
    return LAYERS[unit_name.split(".")[0]]


EDGES: set[tuple[str, str]] = {
    (module, resolved)
    for module, path in MODULES.items()
    for target in imports_of(path)
    if (resolved := resolve(target)) is not None and resolved != module
}


def test_every_unit_has_a_layer():
    units = {unit(m) for m in MODULES}
    unknown = sorted(u for u in units if u.split(".")[0] not in LAYERS)
    assert not unknown, f"give these a layer in LAYERS: {unknown}"


def test_no_edge_against_the_layering():
    bad = []
    for importer, imported in sorted(EDGES):
        a, b = unit(importer), unit(imported)
        if a == b:
            continue
        if layer(a) < layer(b):
            bad.append(f"{importer} -> {imported} (layer {layer(a)} -> {layer(b)})")
        elif layer(a) == layer(b) and (a.split(".")[0], b.split(".")[0]) not in (
            STAGE_EDGES
        ):
            bad.append(f"{importer} -> {imported} (same layer {layer(a)})")
    assert not bad, "imports against the layering:\n" + "\n".join(bad)


def test_io_and_physics_depend_on_nothing_above_them():
    physics = {
        imported
        for importer, imported in EDGES
        if unit(importer) == "physics" and unit(imported) != "physics"
    }
    assert physics <= {"fieldkit.errors"}
    io = {
        unit(imported)
        for importer, imported in EDGES
        if unit(importer) == "io" and unit(imported) != "io"
    }
    assert io <= {
        "errors",
        "outputs",
        "survey",
        "track",
        "impact_table",
        "path_observations",
        "measured",
    }


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of a directed graph as a list of nodes, or None."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt) :] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


@pytest.mark.parametrize("granularity", ["module", "unit"])
def test_no_import_cycle(granularity):
    graph: dict[str, set[str]] = {}
    for importer, imported in EDGES:
        if granularity == "unit":
            importer, imported = unit(importer), unit(imported)
            if importer == imported:
                continue
        graph.setdefault(importer, set()).add(imported)
    cycle = _cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle or [])


def test_the_checker_sees_a_back_edge_and_a_cycle():
    """The checks above can fail: a hidden back-edge and a cycle are found."""
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None
    assert layer(unit("fieldkit.io.gpx")) < layer(unit("fieldkit.reduce.pipeline"))
    assert unit("fieldkit.tracking.video.spin") != unit("fieldkit.tracking.flights.x")
