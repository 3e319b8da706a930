"""The papers' published values, from ``data/published.yaml``.

This is the only place hand-copied numbers enter the pipeline. Callers must
label them "published" wherever they appear.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import yaml

PUBLISHED_FILE = Path(__file__).resolve().parents[1] / "data" / "published.yaml"


@lru_cache(maxsize=1)
def load() -> dict:
    """All published values: ``{"paper_a": {...}, "paper_b": {...}}``."""
    # libyaml's safe loader where PyYAML has it (same document; the pure-Python one is ~7x slower)
    return yaml.load(PUBLISHED_FILE.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def paper_a() -> dict:
    return load()["paper_a"]


def paper_b() -> dict:
    return load()["paper_b"]
