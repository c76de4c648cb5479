"""Where a benchmark run keeps its files under the output folder (see :mod:`samvg.bench.runner`
for the layout), and reading back the records written there."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


class Layout:
    """Where everything of one benchmark lives under ``out``."""

    def __init__(self, out: Path) -> None:
        self.out = out
        self.run_file = out / "run.json"
        self.results_csv = out / "results.csv"

    def record(self, method: str, image_id: str) -> Path:
        return self.out / "records" / method / f"{image_id}.json"

    def svg(self, method: str, image_id: str) -> Path:
        return self.out / "svg" / method / f"{image_id}.svg"

    def render(self, method: str, image_id: str) -> Path:
        return self.out / "renders" / method / f"{image_id}.png"

    def target(self, image_id: str) -> Path:
        return self.out / "targets" / f"{image_id}.png"

    def target_features(self, image_id: str) -> Path:
        return self.out / "fid" / "targets" / f"{image_id}.npy"

    def render_features(self, method: str, image_id: str) -> Path:
        return self.out / "fid" / "renders" / method / f"{image_id}.npy"

    def records(self) -> list[dict[str, Any]]:
        """Every record in the folder, sorted by image id, then method."""
        found = []
        for path in sorted((self.out / "records").glob("*/*.json")):
            try:
                found.append(json.loads(path.read_text(encoding="utf-8")))
            except (OSError, json.JSONDecodeError):
                continue  # a record is written atomically; anything else is not ours
        return sorted(found, key=lambda r: (r.get("id", ""), r.get("method", "")))
