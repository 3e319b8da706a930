"""A test run's background warm-up of the kernel cache (tests/conftest.py,
opnav.core.startup.wait_for_kernels): a process waits for a module the warm-up will fill and has
not yet, and for nothing else."""

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import opnav
from opnav.core import startup


def _spec(monkeypatch, tmp_path, pid, package=None, cache=None):
    progress = tmp_path / "done"
    monkeypatch.setenv(startup.WARMING_ENV, json.dumps({
        "pid": pid, "progress": str(progress), "package": package or str(Path(opnav.__file__).parent),
        "cache": os.environ.get("NUMBA_CACHE_DIR", "") if cache is None else cache}))
    return progress


def test_it_waits_for_a_planned_module_until_warmed(monkeypatch, tmp_path):
    sleeper = subprocess.Popen(["sleep", "30"])
    try:
        progress = _spec(monkeypatch, tmp_path, sleeper.pid)
        progress.write_text("todo: opnav.core.rotations opnav.landing.ekf\nopnav.core.rotations\n")
        assert startup.wait_for_kernels("opnav.core.rotations", poll_s=0.01) < 0.5      # warmed already
        assert startup.wait_for_kernels("opnav._elsewhere", poll_s=0.01) < 0.5          # not one it warms

        def finish():
            time.sleep(0.4)
            with open(progress, "a") as f:
                f.write("opnav.landing.ekf\n")

        threading.Thread(target=finish).start()
        waited = startup.wait_for_kernels("opnav.landing.ekf", poll_s=0.01)
        assert 0.3 < waited < 5                                                        # until its line came
    finally:
        sleeper.kill()
        sleeper.wait()


def test_it_stops_waiting_when_the_warm_up_ends(monkeypatch, tmp_path):
    sleeper = subprocess.Popen(["sleep", "0.3"])
    progress = _spec(monkeypatch, tmp_path, sleeper.pid)
    progress.write_text("todo: opnav.landing.ekf\n")
    t0 = time.perf_counter()
    startup.wait_for_kernels("opnav.landing.ekf", poll_s=0.01)
    assert time.perf_counter() - t0 < 5
    sleeper.wait()


def test_another_copy_or_cache_does_not_wait(monkeypatch, tmp_path):
    sleeper = subprocess.Popen(["sleep", "30"])
    try:
        for kw in ({"package": str(tmp_path / "other" / "opnav")}, {"cache": str(tmp_path / "other-cache")}):
            progress = _spec(monkeypatch, tmp_path, sleeper.pid, **kw)
            progress.write_text("todo: opnav.landing.ekf\n")
            assert startup.wait_for_kernels("opnav.landing.ekf", poll_s=0.01) < 0.5
    finally:
        sleeper.kill()
        sleeper.wait()
