"""Benchmark: time from an ontology edit to the first answer naming the new class, CLI vs server, side by side.

* CLI: ``robokudo ontology add-object NAME --is-a Milk`` then ``robokudo query "find NAME in fridge"``, two
  processes, wall time of both.
* Server: one running ``robokudo serve``; the ``/robokudo/ontology`` service adds the class, then a goal names it:
  wall time from the call to the goal's result.

Each run adds a fresh class (``BenchMilkN``) to a temporary user ontology.

    .venv/bin/python bench/bench_edit_to_answer.py [--runs 5]
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
from typing import Any

from websockets.sync.client import ClientConnection, connect

ROOT = Path(__file__).resolve().parents[1]


def environment(folder: Path) -> dict[str, str]:
    return {
        **os.environ,
        "PYTHONPATH": str(ROOT),
        "ROBOKUDO_USER_ONTOLOGY": str(folder / "user.ttl"),
        "ROBOKUDO_BELIEF_STORE": str(folder / "beliefs.sqlite"),
    }


def robokudo(env: dict[str, str], *argv: str) -> None:
    subprocess.run([sys.executable, "-m", "robokudo", *argv], cwd=ROOT, env=env, check=True, capture_output=True)


def cli_run(env: dict[str, str], name: str) -> float:
    started = time.perf_counter()
    robokudo(env, "ontology", "add-object", name, "--is-a", "Milk")
    robokudo(env, "query", f"find {name} in fridge")
    return time.perf_counter() - started


def reply(connection: ClientConnection, op: str, request_id: str) -> dict[str, Any]:
    while True:
        message = json.loads(connection.recv(timeout=300))
        if message["op"] == op and message.get("id") == request_id:
            return message


def served_run(connection: ClientConnection, name: str) -> float:
    started = time.perf_counter()
    args = {"action": "add", "name": name, "is_a": ["Milk"]}
    connection.send(json.dumps({"op": "call_service", "id": name, "service": "/robokudo/ontology", "args": args}))
    if not reply(connection, "service_response", name)["result"]:
        raise RuntimeError(f"adding {name} failed")
    goal = {"op": "send_action_goal", "id": f"g{name}", "action": "/robokudo/query",
            "args": {"query": f"find {name} in fridge"}}  # fmt: skip
    connection.send(json.dumps(goal))
    if reply(connection, "action_result", f"g{name}")["status"] != 4:
        raise RuntimeError(f"the goal naming {name} did not succeed")
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        env = environment(Path(folder))
        cli = [cli_run(env, f"BenchMilkCli{i}") for i in range(args.runs)]
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            port = probe.getsockname()[1]
        server = subprocess.Popen(
            [sys.executable, "-m", "robokudo", "serve", "--port", str(port)],
            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
        )  # fmt: skip
        try:
            assert server.stdout is not None
            while not server.stdout.readline().startswith("serving on"):
                pass
            with connect(f"ws://127.0.0.1:{port}") as connection:
                served_run(connection, "BenchMilkWarm")  # the first goal loads the models
                served = [served_run(connection, f"BenchMilkServed{i}") for i in range(args.runs)]
        finally:
            server.send_signal(signal.SIGTERM)
            server.wait(60)
    for name, values in (("CLI (add-object + query)", cli), ("server (service + goal)", served)):
        print(f"{name:26s} median {statistics.median(values):.2f} s, max {max(values):.2f} s (n={len(values)})")
    print(f"server / CLI (median): {statistics.median(served) / statistics.median(cli):.2f}")


if __name__ == "__main__":
    main()
