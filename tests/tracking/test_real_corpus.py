"""Real camera clips (issue 31): labels, checksums, and the tracker's done-when checks.

The clips are outside the repository (tests/tracking/real_corpus.py says where they
are looked for); the tests that need them skip, naming the folders searched, when
they are absent.
"""

from __future__ import annotations

import math

import pytest
from real_corpus import (
    CORPUS_ENV,
    EXTENDED_KINDS,
    G_MPS2,
    SURFACE_KINDS,
    clip_file,
    corpus_candidates,
    evaluate_clip,
    find_corpus,
    g_standard_error,
    load_labels,
    refused_contacts,
    result_table,
    scale_of,
    score_events,
    sha256,
)

LABELS = load_labels()
PERMISSIVE = ("MIT", "BSD", "Apache-2.0", "CC0", "CC-BY", "Unlicense", "ISC")
KINDS = (*SURFACE_KINDS, *EXTENDED_KINDS, "hand")


def _corpus_or_skip():
    folder = find_corpus()
    if folder is None:
        searched = ", ".join(str(p) for p in corpus_candidates())
        pytest.skip(f"no clip corpus (set ${CORPUS_ENV}; searched {searched})")
    return folder


def test_the_corpus_has_labelled_clips():
    assert len(LABELS) >= 3
    assert len({label["clip"] for label in LABELS}) == len(LABELS)


@pytest.mark.parametrize("label", LABELS, ids=[lb["clip"] for lb in LABELS])
def test_labels_are_complete_and_consistent(label):
    n = label["frames"]
    assert n > 0 and len(label["sha256"]) == 64
    assert label["source"]["vendorable"] is True
    assert label["source"]["licence"] in PERMISSIVE
    assert label["capture_fps"] > 0 and label["capture_fps_sd"] > 0
    assert label["capture_fps_how"] and label["scale"]["how"]
    _, length_m, rel_sd = scale_of(label)
    assert length_m > 0 and 0 < rel_sd < 0.5
    w, h = label["size_px"]
    u, v, bw, bh = label["body"]["first_box_px"]
    assert 0 <= u and u + bw <= w and 0 <= v and v + bh <= h
    assert 0 <= label["body"]["first_box_frame"] < n
    for c in label["contacts"]:
        assert c["kind"] in KINDS
        assert 0 <= c["first_frame"] <= c["last_frame"] < n
    spans = sorted((f["first_frame"], f["last_frame"]) for f in label["flights"])
    assert all(0 <= a < b < n for a, b in spans)
    # flights follow one another, and no flight overlaps a contact (contacts may
    # overlap each other: a hand pushing a ball at rest)
    assert all(b < c for (_, b), (c, _) in zip(spans, spans[1:], strict=False))
    for c in label["contacts"]:
        assert all(b < c["first_frame"] or a > c["last_frame"] for a, b in spans), (
            c,
            spans,
        )


@pytest.mark.parametrize("label", LABELS, ids=[lb["clip"] for lb in LABELS])
def test_clip_checksum(label):
    folder = _corpus_or_skip()
    path = clip_file(folder, label)
    if not path.exists():
        pytest.skip(f"{path} absent")
    assert sha256(path) == label["sha256"]


def test_g_standard_error_adds_scale_and_rate_in_quadrature():
    # g ~ scale * fps^2: 1 % of rate is 2 % of g
    assert g_standard_error(9.81, 0.0, 0.0, 0.01) == pytest.approx(2 * 0.0981)
    assert g_standard_error(9.81, 0.3, 0.0, 0.0) == pytest.approx(0.3)
    assert g_standard_error(10.0, 0.3, 0.04, 0.0) == pytest.approx(0.5)


def _label(**scale):
    return {
        "capture_fps": 100.0,
        "capture_fps_sd": 0.0,
        "scale": scale
        or {"points_px": [[0, 0], [100, 0]], "length_m": 1.0, "length_sd_m": 0.05},
        "contacts": [
            {"first_frame": 0, "last_frame": 9, "kind": "hand"},
            {"first_frame": 50, "last_frame": 50, "kind": "impact"},
            {"first_frame": 90, "last_frame": 92, "kind": "impact"},
        ],
        "flights": [
            {"first_frame": 11, "last_frame": 49, "free": True},
            {"first_frame": 51, "last_frame": 89, "free": True},
        ],
    }


def test_score_events_finds_misses_and_false_contacts():
    # found within one frame (49 for the contact at 50), a hand contact is not
    # required but not false either (5), 70 is in a free flight: false
    found, missed, false, _ = score_events(_label(), [5, 49, 70], [])
    assert found == [(50, 50, 49)]
    assert missed == [(90, 92)]
    assert false == [70]
    # two frames off is a miss and a false contact
    found, missed, false, _ = score_events(_label(), [52, 94], [])
    assert found == [] and missed == [(50, 50), (90, 92)] and false == [52, 94]
    # an extended contact must begin and end within a frame of the label's
    found, missed, false, _ = score_events(_label(), [(89, 93)], [])
    assert found == [(90, 92, 89)] and missed == [(50, 50)] and not false
    # one spanning a flight and the impact at 50 finds nothing and is false
    found, missed, false, _ = score_events(_label(), [(40, 60)], [])
    assert found == [] and (50, 50) in missed and false == [40]


def test_score_events_checks_g_with_the_scale_uncertainty():
    # scale sd 5 %: g 10.81 +/- 0.2 (fit) has SE sqrt(0.2^2 + 0.5405^2)
    fitted = [(12, 48, 10.81, 0.2), (52, 60, 12.5, 0.2)]
    *_, flights = score_events(_label(), [], fitted)
    first, second = flights
    se = math.hypot(0.2, 0.05 * 10.81)
    assert first.fitted == (12, 48) and first.se_total_mps2 == pytest.approx(se)
    assert first.z == pytest.approx((10.81 - G_MPS2) / se) and first.ok
    se2 = math.hypot(0.2, 0.05 * 12.5)
    assert second.z == pytest.approx((12.5 - G_MPS2) / se2) and not second.ok
    # a flight without a fit fails; a scale from g is not checked for g
    *_, flights = score_events(_label(), [], [(12, 48, 10.81, 0.2)])
    assert flights[1].fitted is None and not flights[1].ok
    label = _label(m_per_px=0.01, m_per_px_sd=0.0005, derived_from_gravity=True)
    *_, flights = score_events(label, [], [(12, 48, 30.0, 0.2), (52, 88, 30.0, 0.2)])
    assert all(f.ok and not f.g_checked for f in flights)


def test_a_flight_fitted_in_a_rolling_contact_misses_it():
    label = {**_label(), "flights": []}
    label["contacts"] = [
        {"first_frame": 0, "last_frame": 8, "kind": "rest"},
        {"first_frame": 9, "last_frame": 50, "kind": "rolling"},
    ]
    # no flight: both found, no event needed
    found, missed, false, flights = score_events(label, [], [])
    assert found == [(0, 8, 0), (9, 50, 9)] and not missed and not false
    assert flights == []
    # a flight one frame into the rest is tolerated; one over 20-40 is not
    found, missed, *_ = score_events(
        label, [30], [(7, 9, 9.8, 0.1), (20, 40, 9.8, 0.1)]
    )
    assert found == [(0, 8, 0)] and missed == [(9, 50)]


def test_only_a_refusal_covering_a_missed_contact_refuses_it():
    # the library refused frames 26-63: the contacts at 29 and 49 lie inside it,
    # 63-64 ends one frame past it (tolerated); 66 and 20-30 are not covered
    missed = [(29, 29), (49, 49), (63, 64), (66, 66), (20, 30)]
    still, refused = refused_contacts(missed, [(26, 63, "why")])
    assert still == [(66, 66), (20, 30)]
    assert refused == [(29, 29, "why"), (49, 49, "why"), (63, 64, "why")]
    # no refusal: every missed contact stays missed
    assert refused_contacts(missed, []) == (missed, [])


def test_a_missing_or_altered_clip_is_reported_not_tracked(tmp_path):
    label = LABELS[0]
    result = evaluate_clip(tmp_path, label)
    assert result.status == "missing" and not result.passed
    path = clip_file(tmp_path, label)
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not the clip")
    result = evaluate_clip(tmp_path, label)
    assert result.status == "bad-checksum" and not result.passed
    assert "FAIL [bad-checksum]" in result_table([result])


@pytest.mark.slow
def test_every_real_clip_is_checked_or_refused_in_one_line():
    """Runs the done-when checks (real_corpus.evaluate_clip) on every clip present and
    prints the table; each clip must be tracked and checked, or refused with a
    one-line error (no traceback). Whether a clip meets the criteria is the table's
    verdict (benchmarks/video_corpus.py prints the same table): many fail with
    today's detection, by design of the issue. Minutes on a loaded 2-core machine."""
    folder = _corpus_or_skip()
    present = [lb for lb in LABELS if clip_file(folder, lb).exists()]
    if not present:
        pytest.skip(f"no labelled clip in {folder}")
    results = [evaluate_clip(folder, label) for label in present]
    print()
    print(result_table(results))
    for label, result in zip(present, results, strict=True):
        assert result.status in ("checked", "refused"), result.lines()
        if result.status == "refused":
            assert result.message.strip() and "\n" not in result.message.strip()
            continue
        # every labelled flight and required contact has a verdict
        free = [f for f in label["flights"] if f.get("free", True)]
        assert len(result.flights) == len(free)
        required = [
            c
            for c in label["contacts"]
            if c["kind"] in (*SURFACE_KINDS, *EXTENDED_KINDS)
        ]
        verdicts = len(result.found) + len(result.missed) + len(result.refused)
        assert verdicts == len(required)
