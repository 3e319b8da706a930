"""Outputs honour the user's umask (atomic writes used to leave mode 0600)."""

import os
import stat

import pytest

from opnav.core import figures
from opnav.core.tables import atomic_target, atomic_write_text


@pytest.fixture(params=[0o022, 0o002, 0o077])
def umask(request):
    old = os.umask(request.param)
    yield request.param
    os.umask(old)


def mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def test_text_and_figures_get_the_umask_mode(tmp_path, umask):
    import matplotlib.pyplot as plt

    atomic_write_text(tmp_path / "t.csv", "a,b\n1,2\n")
    fig, ax = plt.subplots()
    ax.plot([0, 1])
    written = figures.save(fig, tmp_path / "f")
    for p in [tmp_path / "t.csv", *written]:
        assert mode(p) == 0o666 & ~umask, (p.name, oct(mode(p)))
    assert mode(tmp_path / "t.csv") == {0o022: 0o644, 0o002: 0o664, 0o077: 0o600}[umask]


def test_failed_write_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_target(tmp_path / "x.json") as tmp:
            tmp.write_text("partial")
            raise RuntimeError("boom")
    assert list(tmp_path.iterdir()) == []
