"""From the knowledge classifier's evidence (score, margin) to the probability that its best class is right.

The mapping is logistic, ``p = sigmoid(intercept + score_weight * score + margin_weight * margin
+ unread_weight * unread)``, where ``score`` is the best profile's agreement with the object's cues, ``margin`` its
lead over the best profile not related to it by subsumption (see ``knowledge_classifier``) and ``unread`` is 1
when the profile names its class by printed text (milk, mustard) but no text was read on the object, so the
class's own distinguishing cue was never checked. It is fitted by :func:`fit` on labelled objects (was the best
class right?) and checked on others; :data:`FITTED` holds the parameters in use.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Calibration:
    """Logistic calibration parameters (see the module docstring)."""

    intercept: float
    score_weight: float
    margin_weight: float
    unread_weight: float

    def probability(self, score: float, margin: float, unread: bool = False) -> float:
        """The calibrated probability that a best match with this score, margin and unread text is right."""
        z = self.intercept + self.score_weight * score + self.margin_weight * margin + self.unread_weight * unread
        return 1.0 / (1.0 + math.exp(-z)) if z >= 0 else math.exp(z) / (1.0 + math.exp(z))


FITTED = Calibration(intercept=-2.220, score_weight=1.822, margin_weight=6.542, unread_weight=-3.911)
"""The parameters in use: fitted by ``python bench/bench_calibration.py --fit`` (logistic regression, L2 0.1) on
the 105 object answers of the "fit" split (kitchen views table, orbit0, orbit2, orbit4 and the real frames marked
"fit" in ``tests/data/labels/real_objects.json``, each under three queries), then checked on the "check" split
with the same command (without ``--fit``); the script's docstring says what it prints."""


def fit(
    scores: Sequence[float],
    margins: Sequence[float],
    unread: Sequence[bool],
    right: Sequence[bool],
    l2: float = 0.1,
    iterations: int = 50,
) -> Calibration:
    """Logistic regression of ``right`` on (score, margin, unread) by Newton's method with a small L2 penalty on
    the weights (keeps the fit finite when the outcomes separate). ValueError when there is nothing to fit."""
    if not (len(scores) == len(margins) == len(unread) == len(right)) or not scores:
        raise ValueError("fit needs equally many scores, margins, unread flags and outcomes, and at least one")
    x = np.column_stack(
        [np.ones(len(scores)), np.asarray(scores, float), np.asarray(margins, float), np.asarray(unread, float)]
    )
    y = np.asarray(right, dtype=float)
    penalty = np.diag([0.0, l2, l2, l2])
    w = np.zeros(4)
    for _ in range(iterations):
        p = 1.0 / (1.0 + np.exp(-(x @ w)))
        gradient = x.T @ (p - y) + penalty @ w
        hessian = (x.T * (p * (1.0 - p))) @ x + penalty + 1e-9 * np.eye(4)
        step = np.linalg.solve(hessian, gradient)
        w -= step
        if float(np.abs(step).max()) < 1e-10:
            break
    return Calibration(
        intercept=float(w[0]), score_weight=float(w[1]), margin_weight=float(w[2]), unread_weight=float(w[3])
    )
