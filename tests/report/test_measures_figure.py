"""The measures' box plots draw what the table reports: ∞ kept, at a ceiling (issue 35)."""

from __future__ import annotations

import math

import numpy as np

from sumo_ayss.report.sections.measures import with_ceiling


def test_boxes_keep_infinite_values_so_their_median_is_the_tables() -> None:
    a = np.array([1.0, 1.5, 2.0, math.inf, math.inf, math.inf, math.inf])  # median ∞
    b = np.array([0.5, 1.0, 6.0, math.inf, math.inf])  # median 6.0, counting ∞
    drawn, ceiling = with_ceiling([a, b])
    assert ceiling is not None and ceiling > 6.0
    assert np.median(drawn[1]) == np.median(b) == 6.0  # finite-only median would be 1.0
    assert np.median(drawn[0]) == ceiling  # ∞ drawn at the ceiling line
    assert all(np.isfinite(d).all() for d in drawn)
    finite_only, none = with_ceiling([np.array([1.0, 2.0])])
    assert none is None and finite_only[0].tolist() == [1.0, 2.0]
