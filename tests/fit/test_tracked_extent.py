"""The tracked extent: forecasts censored at their first exit, as observed last
samples are (fieldkit/fit/tracked_extent.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fieldkit.errors import ArgumentError
from fieldkit.fit.tracked_extent import (
    Extent,
    censor_chainage,
    censor_segments,
    censor_straight_ensembles,
    exit_chainage,
    parse_extent,
)

BOX = Extent(0.0, 0.0, 10.0, 10.0)


def test_extent_is_checked_and_parsed():
    assert parse_extent(" 1, 2,3 ,4") == Extent(1.0, 2.0, 3.0, 4.0)
    for text, words in (("1,2,3", "four numbers"), ("a,b,c,d", "four numbers"),
                        ("3,0,1,5", "x_min < x_max"), ("0,5,1,5", "y_min < y_max"),
                        ("0,0,inf,1", "not finite")):  # fmt: skip
        with pytest.raises(ArgumentError, match=words) as err:
            parse_extent(text, "tracked_extent")
        assert err.value.source == "tracked_extent"


def test_straight_paths_are_cut_at_the_first_edge_they_cross():
    start = np.array([5.0, 5.0])
    ends = np.array([[5.0, 8.0], [5.0, -5.0], [15.0, 5.0], [20.0, -10.0],
                     [10.0, 10.0], [0.0, 15.0]])  # fmt: skip
    cut_at, cut = censor_segments(start, ends, BOX)
    # (20, -10): leaves through y = 0 at t = 1/3 (x = 10 at t = 1/3 too: the corner)
    expected = [[5, 8], [5, 0], [10, 5], [10, 0], [10, 10], [2.5, 10]]
    np.testing.assert_allclose(cut_at, expected, atol=1e-12)
    assert cut.tolist() == [False, True, True, True, False, True]
    with pytest.raises(ArgumentError, match="outside the extent"):
        censor_segments(np.array([11.0, 5.0]), ends, BOX)


def test_climatology_ensembles_are_cut_member_by_member():
    ens = np.array([[[5.0, -5.0], [5.0, 6.0]], [[1.0, 1.0], [3.0, 3.0]]])
    out, share = censor_straight_ensembles(np.array([[5.0, 5.0], [2.0, 2.0]]), ens,
                                           BOX)  # fmt: skip
    np.testing.assert_allclose(out[0], [[5.0, 0.0], [5.0, 6.0]])
    np.testing.assert_allclose(out[1], ens[1])
    assert share == 0.25


def test_a_polyline_leaves_where_its_first_outbound_segment_crosses():
    # east 4 m, then south 12 m: leaves through y = 0 after 4 + 1 = 5 m
    px, py = np.array([1.0, 5.0, 5.0]), np.array([1.0, 1.0, -11.0])
    assert exit_chainage(px, py, BOX) == pytest.approx(5.0)
    assert exit_chainage(np.array([1.0, 9.0]), np.array([1.0, 9.0]), BOX) == math.inf
    c, cut = censor_chainage(np.array([-2.0, 3.0, 5.0, 7.5]), 5.0)
    assert c.tolist() == [-2.0, 3.0, 5.0, 5.0] and cut.tolist() == [False] * 3 + [True]
    with pytest.raises(ArgumentError, match="starts at"):
        exit_chainage(np.array([-1.0, 5.0]), np.array([1.0, 1.0]), BOX)
