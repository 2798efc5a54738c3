"""Compiled passes of the border pixels (annotators.geometry.border_loops): the foot's breadth-first spread against
a plain breadth-first search that keeps every copy of a node its front reaches."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.geometry.border_loops import _spread


def plain_spread(label: np.ndarray, targets: np.ndarray, rounds: int) -> np.ndarray:
    """Each round every front node passes its label to its unlabelled linked nodes (judged before the round); the
    last to reach a node wins, and every arrival joins the next front in order."""
    label = label.copy()
    front = [int(node) for node in np.flatnonzero(label)]
    for _ in range(rounds):
        arrivals = [(int(t), node) for node in front for t in targets[node] if t >= 0 and label[t] == 0]
        if not arrivals:
            break
        for reached, source in arrivals:
            label[reached] = label[source]
        front = [reached for reached, _ in arrivals]
    return label


def grid_links(rows: int, cols: int, keep: np.ndarray) -> np.ndarray:
    """Nx4 links (left, right, up, down; -1 where none) of a rows x cols grid, each edge kept where ``keep`` (a
    symmetric choice per edge) says so."""
    targets = np.full((rows * cols, 4), -1, dtype=np.int64)
    for node in range(rows * cols):
        row, col = divmod(node, cols)
        for k, (dr, dc) in enumerate(((0, -1), (0, 1), (-1, 0), (1, 0))):
            r, c = row + dr, col + dc
            if 0 <= r < rows and 0 <= c < cols and keep[min(node, r * cols + c), max(node, r * cols + c)]:
                targets[node, k] = r * cols + c
    return targets


@pytest.mark.parametrize("seed", range(20))
def test_the_spread_gives_every_node_the_label_the_plain_search_gives(seed: int) -> None:
    rng = np.random.default_rng(seed)
    rows, cols = 9, 11
    targets = grid_links(rows, cols, rng.random((rows * cols, rows * cols)) < 0.85)
    label = np.zeros(rows * cols, dtype=np.int32)
    starts = rng.choice(rows * cols, size=4, replace=False)
    label[starts] = rng.integers(1, 4, size=4)
    rounds = int(rng.integers(0, 12))
    expected = plain_spread(label, targets, rounds)
    _spread(label, targets, rounds)
    assert np.array_equal(label, expected)
    assert np.count_nonzero(label) > 4 or rounds == 0 or not np.any(targets[starts] >= 0)
