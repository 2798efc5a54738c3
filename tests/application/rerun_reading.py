"""Reading a ``.rrd`` file back with the Rerun SDK's own reader (``rerun.chunk.RrdReader``), for the tests."""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
from rerun.chunk import RrdReader

TIME_COLUMNS = ("tick", "frame_time", "log_time")


@dataclass(frozen=True)
class Row:
    """One logged row: its entity, its tick and frame time (ns; None when not on that timeline), its components."""

    entity: str
    tick: int | None
    frame_time: int | None
    components: dict[str, Any]


@dataclass(frozen=True)
class Recording:
    """Every row of the one recording in a file."""

    recording_ids: tuple[str, ...]
    rows: tuple[Row, ...]

    def of(self, entity: str) -> list[Row]:
        """The rows of ``entity`` (``/world/...``), in tick order."""
        return sorted((r for r in self.rows if r.entity == entity), key=lambda r: (r.tick is None, r.tick or 0))

    def ticks(self, entity: str) -> list[int]:
        """The ticks ``entity`` was logged at, in order."""
        return [r.tick for r in self.of(entity) if r.tick is not None]

    def frame_times(self, entity: str) -> list[int]:
        """The frame times (ns) ``entity`` was logged at, in order of ticks."""
        return [r.frame_time for r in self.of(entity) if r.frame_time is not None]

    def at(self, entity: str, tick: int) -> Row:
        """The last row of ``entity`` logged at ``tick``."""
        return [r for r in self.of(entity) if r.tick == tick][-1]

    def entities(self) -> set[str]:
        """Every entity path logged."""
        return {r.entity for r in self.rows}

    def by_prefix(self, prefix: str) -> dict[str, list[Row]]:
        """The rows of the entities under ``prefix``, by entity."""
        found: dict[str, list[Row]] = defaultdict(list)
        for row in self.rows:
            if row.entity.startswith(prefix):
                found[row.entity].append(row)
        return dict(found)


def _column(batch: pa.RecordBatch, name: str) -> list[Any]:
    column = batch.column(name)
    if pa.types.is_timestamp(column.type):
        column = column.cast(pa.int64())
    return column.to_pylist()


def read_recording(path: Path) -> Recording:
    """The rows of the file's recording (it must hold exactly one)."""
    reader = RrdReader(path)
    recordings = reader.recordings()
    rows = []
    for chunk in reader.stream(store=recordings[0]).to_chunks():
        batch = chunk.to_record_batch()
        names = [n for n in batch.schema.names if n not in TIME_COLUMNS and not n.startswith("rerun.controls")]
        values = {n: _column(batch, n) for n in (*names, *(t for t in TIME_COLUMNS if t in batch.schema.names))}
        for i in range(chunk.num_rows):
            rows.append(
                Row(
                    chunk.entity_path,
                    values["tick"][i] if "tick" in values else None,
                    values["frame_time"][i] if "frame_time" in values else None,
                    {n: values[n][i] for n in names},
                )
            )
    return Recording(tuple(r.recording_id for r in recordings), tuple(rows))


def labels(row: Row, archetype: str) -> list[str]:
    """The labels of a Boxes2D / Boxes3D / Points3D row."""
    return list(row.components.get(f"{archetype}:labels") or [])


def camera_matrices(recording: Recording, tick: int) -> tuple[np.ndarray, np.ndarray]:
    """The camera's 4x4 camera-to-world transform and its 3x3 intrinsics K as logged at ``tick``."""
    transform = recording.at("/world/camera", tick).components
    cam_to_world = np.eye(4)
    cam_to_world[:3, :3] = np.asarray(transform["Transform3D:mat3x3"][0], dtype=np.float64).reshape(3, 3).T
    cam_to_world[:3, 3] = transform["Transform3D:translation"][0]  # (matrices are stored column-major)
    pinhole = recording.at("/world/camera/image", tick).components
    k = np.asarray(pinhole["Pinhole:image_from_camera"][0], dtype=np.float64).reshape(3, 3).T
    return cam_to_world, k
