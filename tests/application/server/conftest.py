"""A ``robokudo serve`` subprocess on the built-in kitchen, shared by the server tests, and a way to start more."""

from __future__ import annotations

import ctypes
import os
import signal
import socket
import subprocess
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
import roslibpy

REPO = Path(__file__).resolve().parents[3]
START_LIMIT = 120.0


@dataclass
class Served:
    """A running server process and where it listens."""

    process: subprocess.Popen[str]
    host: str
    port: int

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def stop(self, timeout: float = 60.0) -> int:
        """SIGTERM the server and wait for its exit status."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.process.wait(timeout)


PR_SET_PDEATHSIG = 1
"""Linux ``prctl`` option: the signal a process gets when the process that started it dies."""


def die_with_tests() -> None:
    """In the server's process before it runs: SIGTERM it when the test process dies, so a test run that is killed
    (a timeout, Ctrl-C twice) leaves no server listening (fixtures' teardown does not run then)."""
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)


def free_port(host: str = "127.0.0.1") -> int:
    """A port nothing listens on right now."""
    with socket.socket() as probe:
        probe.bind((host, 0))
        return int(probe.getsockname()[1])


def start_server(
    folder: Path, *extra: str, host: str = "127.0.0.1", env: dict[str, str] | None = None, port: int | None = None
) -> Served:
    """Start ``robokudo serve`` with its user data in ``folder`` (on ``port``, else a free one); returns once it
    listens."""
    port = port if port is not None else free_port(host)
    environment = {
        **os.environ,
        "PYTHONPATH": str(REPO),
        "ROBOKUDO_USER_ONTOLOGY": str(folder / "user.ttl"),
        "ROBOKUDO_BELIEF_STORE": str(folder / "beliefs.sqlite"),
        "XDG_DATA_HOME": str(folder / "data"),
        **(env or {}),
    }
    command = [sys.executable, "-m", "robokudo", "serve", "--host", host, "--port", str(port), *extra]
    process = subprocess.Popen(
        command,
        cwd=REPO,
        env=environment,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=die_with_tests,
    )
    listening = threading.Event()
    settled = threading.Event()

    def watch() -> None:
        assert process.stdout is not None
        for line in process.stdout:
            if line.startswith("serving on"):
                listening.set()
                settled.set()
        settled.set()  # the output ended: the process exited

    threading.Thread(target=watch, daemon=True).start()
    settled.wait(START_LIMIT)
    if not listening.is_set():
        process.kill()
        process.wait()
        raise RuntimeError(f"robokudo serve did not start: {process.stderr.read() if process.stderr else ''}")
    return Served(process, host, port)


@pytest.fixture(scope="session")
def kitchen_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    """One server on the built-in kitchen for the tests that do not stop it."""
    served = start_server(tmp_path_factory.mktemp("served"))
    yield served
    served.stop()


@pytest.fixture(scope="module")
def ros(kitchen_server: Served) -> Iterator[roslibpy.Ros]:
    """A roslibpy client connected to the kitchen server (one per test module)."""
    client = roslibpy.Ros(host=kitchen_server.host, port=kitchen_server.port)
    client.run()
    yield client
    client.close()


TOKEN = "s3cret"


@pytest.fixture(scope="session")
def guarded_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Served]:
    """A server bound to a non-loopback-default address (127.0.0.2) that requires the token :data:`TOKEN`."""
    served = start_server(tmp_path_factory.mktemp("guarded"), host="127.0.0.2", env={"ROBOKUDO_TOKEN": TOKEN})
    yield served
    served.stop()
