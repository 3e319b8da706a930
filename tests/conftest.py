import os

# One BLAS thread, before anything imports numpy: as every workflow job (Snakemake sets
# OPENBLAS_NUM_THREADS to a job's threads, 1), so the in-process numerics compute what the
# jobs compute, and share the two cores with the background quick build without OpenBLAS
# threads spinning against it. Inherited by the snakemake runs the tests start.
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import atexit  # noqa: E402
import json  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import threading  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

from opnav.snakeio import copy_workflow as _copy_workflow  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def copy_workflow(dst: Path) -> Path:
    """Copy what the workflow needs (not results/ or .snakemake/) into ``dst``."""
    return _copy_workflow(REPO, dst)


def _snakemake_cmd(cwd: Path, *args: str) -> tuple[list[str], dict]:
    """The command and environment of a snakemake run in ``cwd``: its scripts import
    the ``opnav`` copy under ``cwd/src``."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        p for p in (str(Path(cwd) / "src"), os.environ.get("PYTHONPATH", "")) if p))
    return [sys.executable, "-m", "snakemake", *args], env


def run_snakemake(cwd: Path, *args: str, check: bool = False) -> subprocess.CompletedProcess:
    """Run snakemake in ``cwd`` (see :func:`_snakemake_cmd`): ``python -m snakemake``'s
    main() on ``args``, forked from the session's snakemake server (tests/snakemake_server.py:
    the same code, its imports paid once), or a fresh ``python -m snakemake`` with
    OPNAV_TESTS_FORKSERVER=0."""
    cmd, env = _snakemake_cmd(cwd, *args)
    if os.environ.get("OPNAV_TESTS_FORKSERVER", "1") == "0":
        return subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, check=check, env=env)
    rc, out, err = _SnakemakeServer.get().run(Path(cwd), list(args), env)
    proc = subprocess.CompletedProcess(cmd, rc, out, err)
    if check:
        proc.check_returncode()
    return proc


class _SnakemakeServer:
    """Client of tests/snakemake_server.py: one server per session, started at the
    first run, requests from any thread (each its own forked child), stopped at exit."""

    _instance = None
    _start_lock = threading.Lock()

    @classmethod
    def get(cls) -> "_SnakemakeServer":
        with cls._start_lock:
            if cls._instance is None or cls._instance.proc.poll() is not None:
                cls._instance = cls()
            return cls._instance

    def __init__(self):
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("snakemake_server.py"))],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert "ready" in json.loads(self.proc.stdout.readline())
        self.tmp = Path(tempfile.mkdtemp(prefix="snakemake-server-"))
        self.lock = threading.Lock()
        self.next_id = 0
        self.replies: dict[int, int] = {}
        self.events: dict[int, threading.Event] = {}
        threading.Thread(target=self._read, daemon=True).start()
        atexit.register(self.close)

    def _read(self):
        for line in self.proc.stdout:
            msg = json.loads(line)
            with self.lock:
                self.replies[msg["id"]] = msg["rc"]
                self.events[msg["id"]].set()
        with self.lock:                      # the server died: wake every waiter
            for ev in self.events.values():
                ev.set()

    def run(self, cwd: Path, args: list[str], env: dict) -> tuple[int, str, str]:
        with self.lock:
            rid = self.next_id
            self.next_id += 1
            ev = self.events[rid] = threading.Event()
            out, err = self.tmp / f"{rid}.out", self.tmp / f"{rid}.err"
            self.proc.stdin.write(json.dumps({"id": rid, "cwd": str(cwd), "argv": args, "env": env,
                                              "stdout": str(out), "stderr": str(err)}) + "\n")
            self.proc.stdin.flush()
        ev.wait()
        with self.lock:
            rc = self.replies.pop(rid, None)
            del self.events[rid]
        assert rc is not None, "the snakemake server died"
        texts = [p.read_text(errors="replace") for p in (out, err)]
        out.unlink()
        err.unlink()
        return rc, *texts

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(timeout=600)
        shutil.rmtree(self.tmp, ignore_errors=True)


@pytest.fixture()
def workdir(tmp_path: Path) -> Path:
    return copy_workflow(tmp_path)


# ------------------------------------------------------------ the shared quick build
# One complete quick-profile run serves every test that needs finished results (the
# end-to-end test and the dry-run tests of test_incremental). It starts in the
# background at the first test of the session, if any collected test uses it, and
# those tests run last: the build overlaps the rest of the suite instead of adding
# its wall time to it.
QUICK_FIXTURE = "quick_results"


def _uses_quick_build(item) -> bool:
    return QUICK_FIXTURE in getattr(item, "fixturenames", ())


def pytest_collection_modifyitems(config, items):
    """Tests that read the shared quick build run after all others (order kept otherwise)."""
    items.sort(key=_uses_quick_build)


@pytest.fixture(scope="session", autouse=True)
def _quick_build(request, tmp_path_factory):
    """The background quick-profile run: (workdir, process, log file), or None when
    no selected test needs it. Stopped (with its jobs) when the session ends."""
    if not any(_uses_quick_build(it) for it in request.session.items):
        yield None
        return
    wd = copy_workflow(tmp_path_factory.mktemp("quick"))
    log_path = wd / "quick-build.log"
    cmd, env = _snakemake_cmd(wd, "--cores", "2", "--configfile", "config/quick.yaml")
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, cwd=wd, env=env, stdout=log, stderr=subprocess.STDOUT,
                                start_new_session=True)
    try:
        yield wd, proc, log_path
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGTERM)
            try:
                proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()


@pytest.fixture(scope="session")
def quick_results(_quick_build) -> Path:
    """A scratch copy of the workflow after one complete quick-profile run (shared by
    the end-to-end test and the dry-run tests that need recorded provenance)."""
    wd, proc, log_path = _quick_build
    assert proc.wait() == 0, log_path.read_text()[-4000:]
    return wd


def dry_run_jobs(cwd: Path, *args: str) -> list[tuple[str, dict]]:
    """The jobs ``snakemake -n`` lists, as (rule, wildcards) pairs."""
    return _dry_run_jobs(run_snakemake(cwd, "-n", "--cores", "1", *args))


def dry_run_jobs_many(cwd: Path, arg_lists: list[tuple[str, ...]], workers: int = 2) -> list[list[tuple[str, dict]]]:
    """:func:`dry_run_jobs` for each argument tuple, ``workers`` at a time (a dry run
    takes no lock and is single-threaded, so two use both cores)."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=workers) as pool:
        procs = list(pool.map(lambda a: run_snakemake(cwd, "-n", "--cores", "1", *a), arg_lists))
    return [_dry_run_jobs(p) for p in procs]


def _dry_run_jobs(proc: subprocess.CompletedProcess) -> list[tuple[str, dict]]:
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    jobs = []
    for block in re.split(r"\n(?=(?:local)?rule \w+:\n)", proc.stdout):
        m = re.match(r"(?:local)?rule (\w+):\n", block.lstrip("\n"))
        if not m:
            continue
        wc = re.search(r"^    wildcards: (.*)$", block, re.M)
        pairs = dict(kv.split("=", 1) for kv in wc.group(1).split(", ")) if wc else {}
        jobs.append((m.group(1), pairs))
    return jobs


# ------------------------------------------------------------ hypothesis
# The same examples on every run (CI included): a property test that fails on one
# clone fails on every clone, and a green suite stays green. `HYPOTHESIS_PROFILE=explore
# pytest` draws fresh examples (more of them) to hunt for new counterexamples.
from hypothesis import settings as _hyp_settings  # noqa: E402

_hyp_settings.register_profile("repro", derandomize=True)
_hyp_settings.register_profile("explore", derandomize=False, max_examples=200)
_hyp_settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repro"))
