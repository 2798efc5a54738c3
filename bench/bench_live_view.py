"""Benchmark of the live view in a real browser (headless Debian Chromium driven by selenium), run on demand.

* Page update latency: a ``robokudo serve`` on the kitchen ticks at 30 Hz; the bench subscribes to
  ``/robokudo/tree_status`` itself to learn each tick's server time stamp, and a MutationObserver in the page
  records when the page's tick counter shows that tick. Latency = DOM update time - server stamp (one machine, one
  clock). Reported: median and p95, and how many ticks the page showed out of those published.
* Server CPU with the page open vs closed: user + system CPU seconds of the server process over the same wall time,
  first without the page, then with it open (idle engine at 30 Hz, the bench's own tree-status subscriber connected
  both times). Goal: the page costs <= 10% of one core extra; the ratio of the two figures is printed too.

    .venv/bin/python bench/bench_live_view.py [--seconds 20]
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
import threading
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.support.ui import WebDriverWait
from websockets.sync.client import connect

REPO = Path(__file__).resolve().parents[1]
CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
LATENCY_GOAL_NOTE = "no goal set by the issue; reported"
CPU_GOAL = 0.10

OBSERVER = """
window.__shown = [];
const tick = document.getElementById('tick');
new MutationObserver(() => {
  window.__shown.push([tick.textContent, performance.timeOrigin + performance.now()]);
}).observe(tick, {childList: true, characterData: true, subtree: true});
"""


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def start_server(folder: Path, port: int) -> subprocess.Popen[str]:
    env = {
        **os.environ,
        "PYTHONPATH": str(REPO),
        "ROBOKUDO_USER_ONTOLOGY": str(folder / "user.ttl"),
        "ROBOKUDO_BELIEF_STORE": str(folder / "beliefs.sqlite"),
    }
    command = [sys.executable, "-m", "robokudo", "serve", "--port", str(port), "--rate", "30"]
    process = subprocess.Popen(command, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    assert process.stdout is not None
    for line in process.stdout:
        if line.startswith("serving on"):
            threading.Thread(target=lambda: [None for _ in process.stdout], daemon=True).start()  # type: ignore[union-attr]
            return process
    raise RuntimeError("robokudo serve did not start")


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def browser() -> webdriver.Chrome:
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
    ):
        options.add_argument(flag)
    os.environ.setdefault("SE_OFFLINE", "true")
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seconds", type=float, default=20.0, help="length of each measured phase")
    args = parser.parse_args()
    port = free_port()
    with tempfile.TemporaryDirectory() as folder:
        server = start_server(Path(folder), port)
        try:
            time.sleep(2.0)
            with connect(f"ws://127.0.0.1:{port}/") as socket_client:  # the same bench subscriber as below
                socket_client.send(json.dumps({"op": "subscribe", "topic": "/robokudo/tree_status"}))
                before = cpu_seconds(server.pid)
                end = time.monotonic() + args.seconds
                while time.monotonic() < end:
                    socket_client.recv(timeout=5)
                closed_cpu = cpu_seconds(server.pid) - before

            driver = browser()
            try:
                driver.get(f"http://127.0.0.1:{port}/")
                WebDriverWait(driver, 60).until(
                    lambda d: d.find_element("id", "connection").get_attribute("data-state") == "connected"
                )
                driver.execute_script(OBSERVER)
                stamps: dict[int, float] = {}
                with connect(f"ws://127.0.0.1:{port}/") as socket_client:
                    socket_client.send(json.dumps({"op": "subscribe", "topic": "/robokudo/tree_status"}))
                    before = cpu_seconds(server.pid)
                    end = time.monotonic() + args.seconds
                    while time.monotonic() < end:
                        message = json.loads(socket_client.recv(timeout=5))
                        if message.get("op") == "publish":
                            stamps[message["msg"]["tick"]] = message["msg"]["stamp"]
                    open_cpu = cpu_seconds(server.pid) - before
                shown = driver.execute_script("return window.__shown")
            finally:
                driver.quit()
        finally:
            server.send_signal(signal.SIGTERM)
            server.wait(60)
    latencies = []
    for text, when_ms in shown:
        tick = int(text.split()[-1])
        if tick in stamps:
            latencies.append(when_ms / 1000.0 - stamps[tick])
    latencies.sort()
    median = statistics.median(latencies) * 1e3
    p95 = latencies[int(0.95 * (len(latencies) - 1))] * 1e3
    print(
        f"page update latency (tick -> DOM), 30 Hz: median {median:.1f} ms, p95 {p95:.1f} ms "
        f"({len(latencies)} of {len(stamps)} published ticks shown) — {LATENCY_GOAL_NOTE}"
    )
    extra = (open_cpu - closed_cpu) / args.seconds  # of one core
    verdict = "met" if extra <= CPU_GOAL else "NOT met"
    print(
        f"server CPU over {args.seconds:g} s (both phases with the bench's own tree-status subscriber): page closed "
        f"{closed_cpu:.2f} s, page open {open_cpu:.2f} s: {100 * extra:+.1f}% of one core "
        f"(goal <= {100 * CPU_GOAL:.0f}%: {verdict}; {open_cpu / max(closed_cpu, 1e-9):.1f}x the closed figure)"
    )


if __name__ == "__main__":
    main()
