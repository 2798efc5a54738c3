"""Would a compiled (numba) kernel pay for the association's geometric costs? (issue 19, goal 1): an experiment,
not a benchmark.

On frames captured from ``BeliefStore.integrate`` (bench frames at random places and from fixed views, 10,000
stored), it times ``gated_costs`` (numpy) against two numba kernels over the same arrays, and counts the pair costs
whose bits differ from numpy's:

* ``kernel, numpy log/exp``: the distance pre-gate, the world test and the size gate in one compiled loop; the
  typical sizes (exp of the mean log extent) and the log of the size ratio stay numpy calls, so the only source of
  a difference is the distance's summation order (numpy's einsum adds ``(x² + z²) + y²`` on this machine);
* ``kernel, all compiled``: the typical sizes and the log ratio in the kernel too (libm's exp/log, which differ
  from numpy's SIMD ones by 1 ulp on a few per cent of inputs on an AVX-512 machine).

It also times, in fresh processes, ``import numba`` and the first call of a cached kernel (what every process
that integrates would pay once). Nothing here is used by the store.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/compiled_association.py [--frames N] [--repeats N]``
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numba
import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))
sys.path.insert(0, str(BENCH / "experiments"))

import bench_beliefs as bench  # noqa: E402
import frame_python  # noqa: E402

from reasoning.beliefs import store as store_module  # noqa: E402
from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.association import (  # noqa: E402
    AssociationConfig,
    GatedPairs,
    Trackable,
    _positions,
    gated_costs,
    typical_sizes,
)
from reasoning.fusion.frame import WORLD_FRAME  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402


@numba.njit(cache=True)
def _sized_near_pairs(
    a: np.ndarray, b: np.ndarray, size_a: np.ndarray, size_b: np.ndarray, gate: float, sigma: float, ratio_gate: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Pairs within ``gate`` (row-major), their position term, and their size ratio (0 when a size is missing)."""
    n, m = a.shape[0], b.shape[0]
    rows = np.empty(n * m, np.int64)
    cols = np.empty(n * m, np.int64)
    total = np.empty(n * m)
    ratio = np.empty(n * m)
    k = 0
    for i in range(n):
        for j in range(m):
            dx, dy, dz = a[i, 0] - b[j, 0], a[i, 1] - b[j, 1], a[i, 2] - b[j, 2]
            distance = math.sqrt((dx * dx + dz * dz) + dy * dy)
            if not distance <= gate:
                continue
            r = 0.0
            if size_a[i] > 0 and size_b[j] > 0:
                r = max(size_a[i], size_b[j]) / min(size_a[i], size_b[j])
                if not r <= ratio_gate:
                    continue
            rows[k], cols[k], ratio[k] = i, j, r
            term = distance / sigma
            total[k] = term * term
            k += 1
    return rows[:k], cols[:k], total[:k], ratio[:k]


@numba.njit(cache=True)
def _typical(extents: np.ndarray) -> np.ndarray:
    out = np.empty(extents.shape[0])
    for i in range(extents.shape[0]):
        out[i] = math.exp((math.log(extents[i, 0]) + math.log(extents[i, 1]) + math.log(extents[i, 2])) / 3.0)
    return out


@numba.njit(cache=True)
def _all_compiled(
    a: np.ndarray, b: np.ndarray, ea: np.ndarray, eb: np.ndarray, gate: float, sigma: float, ratio_gate: float,
    size_sigma: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    size_a, size_b = _typical(ea), _typical(eb)
    rows, cols, total, ratio = _sized_near_pairs(a, b, size_a, size_b, gate, sigma, ratio_gate)
    for k in range(total.size):
        if ratio[k] > 0:
            term = math.log(ratio[k]) / size_sigma
            total[k] += term * term
    return rows, cols, total


def _one_world(observations: Sequence[Trackable], beliefs: Sequence[Trackable]) -> bool:
    return all(o.frame == WORLD_FRAME for o in observations) and all(b.frame == WORLD_FRAME for b in beliefs)


def _plain(item: Trackable) -> bool:
    """No histogram, and a size."""
    return item.appearance is None and item.dimensions is not None


def kernel_numpy_logs(
    observations: Sequence[Trackable], beliefs: Sequence[Trackable], config: AssociationConfig
) -> GatedPairs:
    """``gated_costs`` of frames in one world without histograms: the loop compiled, exp/log by numpy."""
    rows, cols, total, ratio = _sized_near_pairs(
        _positions(observations), _positions(beliefs), typical_sizes(observations), typical_sizes(beliefs),
        config.gate_distance, config.position_sigma, config.size_ratio_gate,
    )  # fmt: skip
    sized = ratio > 0
    total += np.where(sized, (np.log(np.where(sized, ratio, 1.0)) / config.size_sigma) ** 2, 0.0)
    return GatedPairs((len(observations), len(beliefs)), rows, cols, total, np.zeros(rows.size, dtype=bool))


def kernel_all_compiled(
    observations: Sequence[Trackable], beliefs: Sequence[Trackable], config: AssociationConfig
) -> GatedPairs:
    """``gated_costs`` of frames in one world without histograms, every sized item: all in the kernel."""
    rows, cols, total = _all_compiled(
        _positions(observations), _positions(beliefs),
        np.array([o.dimensions for o in observations], dtype=np.float64),
        np.array([b.dimensions for b in beliefs], dtype=np.float64),
        config.gate_distance, config.position_sigma, config.size_ratio_gate, config.size_sigma,
    )  # fmt: skip
    return GatedPairs((len(observations), len(beliefs)), rows, cols, total, np.zeros(rows.size, dtype=bool))


def cold_seconds(code: str, repeats: int) -> float:
    """The least wall time of ``code`` in a fresh interpreter."""
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True, cwd=BENCH.parent)
        best = min(best, time.perf_counter() - start)
    return best


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=150)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        path = Path(name) / "seed.sqlite"
        frames = frame_python.seeded_frames(path, args.frames)
        tracker = BeliefTracker(class_test=bench.is_subclass)
        store = BeliefStore(path, tracker=tracker)
        captured = frame_python.captured_frames(store, frames)
        update = store._row_update(tracker)
        cases = [(objects, [store_module._Candidate(row, update) for row in rows]) for rows, objects, _ in captured]
        store.close()
    config = tracker.config.association
    usable = [(o, c) for o, c in cases if _one_world(o, c) and all(_plain(x) for x in [*o, *c])]
    print(f"frames {len(cases)}, {len(usable)} in one world without histograms, every item sized (timed below)")
    ways: dict[str, Callable[..., GatedPairs]] = {
        "gated_costs (numpy)": gated_costs,
        "kernel, numpy log/exp": kernel_numpy_logs,
        "kernel, all compiled": kernel_all_compiled,
    }
    for way in ways.values():
        way(*usable[0], config)  # compiled (or loaded from the cache) before timing
    best = dict.fromkeys(ways, math.inf)
    for _ in range(args.repeats):
        for label, way in ways.items():  # alternating
            start = time.process_time_ns()
            for observations, candidates in usable:
                way(observations, candidates, config)
            best[label] = min(best[label], (time.process_time_ns() - start) / 1000 / len(usable))
    reference = [gated_costs(o, c, config) for o, c in usable]
    for label, way in ways.items():
        pairs = differ = 0
        for (observations, candidates), expected in zip(usable, reference, strict=True):
            got = way(observations, candidates, config)
            same_pairs = np.array_equal(got.rows, expected.rows) and np.array_equal(got.cols, expected.cols)
            assert same_pairs, label
            pairs += got.costs.size
            differ += int((got.costs != expected.costs).sum())
        print(f"{label:24s} min {best[label]:6.1f} us per frame; pair costs with other bits: {differ} of {pairs}")
    start_numba = cold_seconds("import numba", 3)
    start_numpy = cold_seconds("import numpy", 3)
    first_call = cold_seconds(
        "import sys; sys.path[:0] = ['bench', 'bench/experiments']; import numpy as np;"
        "from compiled_association import _sized_near_pairs as k; z = np.zeros((1, 3)); s = np.ones(1);"
        "k(z, z, s, s, 0.15, 0.05, 2.5)",
        3,
    )
    print(f"cold process: import numpy {start_numpy:.3f} s, import numba {start_numba:.3f} s,")
    print(f"  import this script + first call of the cached kernel {first_call:.3f} s (seeding imports included)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
