"""The executor's verdicts on columns (laplace_springs.policy.judge_columns) against a plain
Python reading of the contract: per column, the largest bound over max(max |value|, S₀)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from laplace_springs.policy import column_verdicts, judge_columns


def _by_hand(values: np.ndarray, bounds: np.ndarray, floor: float) -> list[float]:
    out = []
    for j in range(values.shape[1]):
        column = [abs(float(v)) for v in values[:, j]]
        tops = [float(b) for b in bounds[:, j]]
        if not all(math.isfinite(v) for v in column + tops):
            out.append(math.inf)
            continue
        top, scale = max(tops), max(*column, floor)
        out.append(0.0 if top == 0 else top / scale if scale > 0 else math.inf)
    return out


def _cases() -> list[tuple[np.ndarray, np.ndarray, float]]:
    rng = np.random.default_rng(7)
    cases = []
    for _ in range(40):
        n, m = int(rng.integers(1, 5)), int(rng.integers(1, 9))
        values = rng.normal(size=(n, m)) * 10.0 ** rng.integers(-5, 5, size=(n, m))
        bounds = np.abs(rng.normal(size=(n, m))) * 10.0 ** rng.integers(-18, -10, size=(n, m))
        for _ in range(int(rng.integers(0, 3))):  # a non-finite number here and there
            i, j = int(rng.integers(n)), int(rng.integers(m))
            (values if rng.random() < 0.5 else bounds)[i, j] = rng.choice([np.nan, np.inf])
        cases.append((values, bounds, float(rng.choice([0.0, 1e-3, 1.0, 50.0]))))
    return cases


@pytest.mark.parametrize("case", range(40))
def test_verdicts_follow_the_contract(case: int) -> None:
    values, bounds, floor = _cases()[case]
    expected = _by_hand(values, bounds, floor)
    for target in (1e-13, 1e-16, 1e-3):
        verdict = judge_columns(np.abs(values), bounds, floor, target)
        assert np.allclose(verdict.relative, expected, rtol=1e-15, atol=0)
        assert verdict.pending.tolist() == [not r <= target for r in expected]
        # the summary: an upper bound of the worst column, and the largest |value|
        assert verdict.worst >= max(expected)
        largest = np.abs(values).max()
        assert verdict.largest == largest or (math.isnan(verdict.largest) and math.isnan(largest))
        pending, relative = column_verdicts(values, bounds, floor, target)
        assert pending.tolist() == verdict.pending.tolist()


def test_no_columns() -> None:
    verdict = judge_columns(np.zeros((2, 0)), np.zeros((2, 0)), 1.0, 1e-13)
    assert verdict.pending.size == 0 and verdict.worst == 0.0
