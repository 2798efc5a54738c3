"""The user ontology file as a transaction target: an exclusive lock, a consistent read, a checked atomic replace.

Every edit of the user file holds an exclusive ``flock`` on ``<file>.lock`` (released by the kernel when the process
dies, so a killed editor never leaves it locked) from reading the file to replacing it. :meth:`UserLayerFile.read`
takes the file's bytes and change stamp; :meth:`UserLayerFile.replace` writes a temporary file, fsyncs it and renames
it over the user file, but only when the file still has the bytes that were read: an edit made meanwhile by someone
who does not take the lock (a text editor) raises :class:`ChangedMeanwhileError` instead of being overwritten.
Temporary files left by a killed editor are removed by the next one.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from reasoning.knowledge.atomic_write import write_atomically
from reasoning.knowledge.sources import Stamp


class LockTimeoutError(TimeoutError):
    """Another edit held the user file's lock for longer than the timeout."""


class ChangedMeanwhileError(RuntimeError):
    """The user file changed between reading it and replacing it."""


@dataclass(frozen=True)
class Snapshot:
    """The user file as read under the lock: its bytes (empty when it does not exist) and change stamp."""

    data: bytes
    stamp: Stamp | None

    @property
    def exists(self) -> bool:
        """True when the file existed."""
        return self.stamp is not None

    @property
    def text(self) -> str:
        """The content as text (UTF-8)."""
        return self.data.decode("utf-8")


def lock_path(user_file: Path) -> Path:
    """The lock file of a user file: ``<file>.lock`` beside it."""
    return user_file.with_name(user_file.name + ".lock")


class UserLayerFile:
    """Locked reads and checked atomic replacements of one user ontology file."""

    def __init__(self, path: Path, lock_timeout: float = 60.0) -> None:
        self.path = Path(path)
        self.lock_timeout = lock_timeout

    @contextlib.contextmanager
    def locked(self) -> Iterator[None]:
        """Hold the exclusive lock (waiting at most ``lock_timeout`` seconds, else LockTimeoutError)."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        descriptor = os.open(lock_path(self.path), os.O_RDWR | os.O_CREAT, 0o644)
        try:
            deadline = time.monotonic() + self.lock_timeout
            while True:
                try:
                    fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
                    break
                except BlockingIOError:
                    if time.monotonic() >= deadline:
                        raise LockTimeoutError(
                            f"another edit has held {lock_path(self.path)} for {self.lock_timeout:g} s"
                        ) from None
                    time.sleep(0.01)
            try:
                self._remove_stale_temporaries()
                yield
            finally:
                fcntl.flock(descriptor, fcntl.LOCK_UN)
        finally:
            os.close(descriptor)

    def read(self) -> Snapshot:
        """The file's bytes and stamp, taken from one open file (empty and None when it does not exist)."""
        try:
            with open(self.path, "rb") as stream:
                status = os.fstat(stream.fileno())
                data = stream.read()
        except FileNotFoundError:
            return Snapshot(b"", None)
        return Snapshot(data, (status.st_mtime_ns, status.st_size, status.st_ino))

    def replace(self, read: Snapshot, data: bytes) -> None:
        """Atomically replace the file with ``data`` if it still holds what ``read`` saw (call with the lock held)."""
        if self.read().data != read.data or self.path.exists() != read.exists:
            raise ChangedMeanwhileError(f"{self.path} changed while the edit was being validated")
        write_atomically(self.path, data)

    def _remove_stale_temporaries(self) -> None:
        """Temporary files of an editor that was killed before renaming (only lock holders write them)."""
        for leftover in self.path.parent.glob(f".{self.path.name}.{'?' * 8}.tmp"):  # write_atomically's names
            with contextlib.suppress(FileNotFoundError):
                leftover.unlink()
