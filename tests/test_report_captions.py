"""Every report caption is valid reStructuredText: docutils reports nothing."""

import io
from pathlib import Path

import pytest

from conftest import REPO

docutils_core = pytest.importorskip("docutils.core")

CAPTIONS = sorted((REPO / "workflow" / "report").glob("*.rst"))


def test_there_are_captions():
    assert len(CAPTIONS) >= 10


@pytest.mark.parametrize("path", CAPTIONS, ids=lambda p: p.name)
def test_caption_renders_without_messages(path: Path):
    warnings = io.StringIO()
    docutils_core.publish_doctree(
        path.read_text(), source_path=str(path),
        settings_overrides={"report_level": 1, "halt_level": 5, "warning_stream": warnings})
    assert warnings.getvalue() == "", warnings.getvalue()
