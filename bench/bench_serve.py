"""Benchmark of serving: warm served answer (``robokudo serve`` + a WebSocket goal) vs a cold ``robokudo query``.

Goal (issue 14): the served goal -> result latency is at most 1/10 of the cold CLI's for "find milk in fridge"
on the built-in kitchen. Both run side by side in one run; the figures are the median and p95 in seconds.

Run: ``.venv/bin/python bench/bench_serve.py [--goals N] [--cold N]``
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from websockets.sync.client import connect

ROOT = Path(__file__).resolve().parents[1]
QUERY = "find milk in fridge"


def percentile(values: list[float], share: float) -> float:
    """The ``share`` quantile of ``values`` (nearest rank)."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(share * (len(ordered) - 1)))]


def served(goals: int, environment: dict[str, str]) -> list[float]:
    """Goal -> result latencies of ``goals`` goals sent one after the other to one served kitchen."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command = [sys.executable, "-m", "robokudo", "serve", "--port", str(port)]
    process = subprocess.Popen(command, cwd=ROOT, env=environment, stdout=subprocess.PIPE, text=True)
    try:
        assert process.stdout is not None
        while not process.stdout.readline().startswith("serving on"):
            pass
        latencies = []
        with connect(f"ws://127.0.0.1:{port}") as connection:
            for number in range(goals + 1):
                goal_id = f"g{number}"
                started = time.perf_counter()
                message = {
                    "op": "send_action_goal",
                    "id": goal_id,
                    "action": "/robokudo/query",
                    "args": {"query": QUERY},
                }
                connection.send(json.dumps(message))
                while True:
                    reply = json.loads(connection.recv())
                    if reply["op"] == "action_result" and reply["id"] == goal_id:
                        break
                if reply["status"] != 4:
                    raise RuntimeError(f"goal {goal_id} ended {reply}")
                if number:  # the first goal warms the process up
                    latencies.append(time.perf_counter() - started)
        return latencies
    finally:
        process.send_signal(signal.SIGTERM)
        process.wait(60)


def cold(runs: int, environment: dict[str, str]) -> list[float]:
    """Wall times of ``runs`` ``robokudo query`` processes."""
    latencies = []
    for _ in range(runs):
        started = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "robokudo", "query", QUERY],
            cwd=ROOT,
            env=environment,
            check=True,
            stdout=subprocess.DEVNULL,
        )
        latencies.append(time.perf_counter() - started)
    return latencies


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals", type=int, default=20, help="served goals (default 20)")
    parser.add_argument("--cold", type=int, default=5, help="cold CLI runs (default 5)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        environment = {
            **os.environ,
            "PYTHONPATH": str(ROOT),
            "ROBOKUDO_USER_ONTOLOGY": str(Path(folder) / "user.ttl"),
            "ROBOKUDO_BELIEF_STORE": str(Path(folder) / "beliefs.sqlite"),
        }
        warm = served(args.goals, environment)
        cli = cold(args.cold, environment)
    for name, values in (("served", warm), ("cold CLI", cli)):
        median, p95 = statistics.median(values), percentile(values, 0.95)
        print(f"{name:>9}: median {median:.3f} s  p95 {p95:.3f} s  (n={len(values)})")
    ratio = statistics.median(warm) / statistics.median(cli)
    print(f"served / cold (median): {ratio:.3f}  (goal <= 0.1)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
