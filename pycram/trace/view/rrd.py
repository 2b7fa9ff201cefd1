"""Reading a view's ``.rrd`` recording back (Rerun's Python API): what is in it.

`RecordingContents.read(path)`: the recording's id, its entity paths, and how many rows (logged
values on a timeline) each entity has -- e.g. ``rows["/tree/status"]`` is the number of
task-status changes the view logged. For tests, `pycram view` and anyone checking a recording.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["RecordingContents"]


@dataclass(frozen=True)
class RecordingContents:
    """What an ``.rrd`` holds: `recording_id`, `entity_paths` (each starting with "/"), `rows`
    per entity path (temporal rows; static data is in `static`)."""

    path: Path
    recording_id: str | None
    entity_paths: frozenset[str]
    rows: Counter[str] = field(default_factory=Counter)
    static: frozenset[str] = frozenset()

    @classmethod
    def read(cls, path: str | Path) -> RecordingContents:
        """Read the recording in `path` (its first recording store). Raises `ValueError` when the
        file holds no recording."""
        from rerun.chunk import RrdReader

        reader = RrdReader(str(path))
        stores = reader.recordings()
        if not stores:
            raise ValueError(f"{path} holds no Rerun recording")
        store = reader.store(store=stores[0])
        rows: Counter[str] = Counter()
        static: set[str] = set()
        for chunk in store.stream().to_chunks():
            entity = str(chunk.entity_path)
            if chunk.is_static:
                static.add(entity)
            else:
                rows[entity] += int(chunk.num_rows)
        recording_id = getattr(stores[0], "recording_id", None) or getattr(stores[0], "id", None)
        return cls(
            Path(path),
            None if recording_id is None else str(recording_id),
            frozenset(str(p) for p in store.schema().entity_paths()),
            rows,
            frozenset(static),
        )

    def has(self, prefix: str) -> bool:
        """Whether some entity path starts with `prefix` (give it with its leading "/")."""
        return any(p == prefix or p.startswith(prefix.rstrip("/") + "/") for p in self.entity_paths)
