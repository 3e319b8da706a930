import os

# One BLAS thread, before anything imports numpy: as every workflow job (Snakemake sets
# OPENBLAS_NUM_THREADS to a job's threads, 1), so the in-process numerics compute what the
# jobs compute, and share the two cores with the background quick build without OpenBLAS
# threads spinning against it. Inherited by the snakemake runs the tests start.
os.environ["OPENBLAS_NUM_THREADS"] = "1"

import atexit  # noqa: E402
import json  # noqa: E402
import re  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import signal  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import threading  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402

from opnav.core.snakeio import copy_workflow as _copy_workflow  # noqa: E402

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


def run_snakemake(cwd: Path, *args: str, check: bool = False, hide: tuple[str, ...] = (),
                  timeout: float | None = None) -> subprocess.CompletedProcess:
    """Run snakemake in ``cwd`` (see :func:`_snakemake_cmd`): ``python -m snakemake``'s
    main() on ``args``, forked from the session's snakemake server (tests/snakemake_server.py:
    the same code, its imports paid once), or a fresh ``python -m snakemake`` with
    OPNAV_TESTS_FORKSERVER=0. ``hide``: modules the run sees as not installed; past
    ``timeout`` seconds, subprocess.TimeoutExpired."""
    proc = start_snakemake(cwd, *args, hide=hide).wait(timeout)
    if check:
        proc.check_returncode()
    return proc


class SnakemakeRun:
    """A snakemake run started by :func:`start_snakemake`: ``pid`` (it leads its own
    process group when started with ``new_session``), ``poll()``, ``wait(timeout)`` -> the
    CompletedProcess (stdout and stderr apart; subprocess.TimeoutExpired past ``timeout``)."""

    def __init__(self, cmd, popen=None, server=None, rid=None):
        self.cmd, self._popen, self._server, self._rid = cmd, popen, server, rid
        self._done = None
        self.pid = popen.pid if popen is not None else server.pid_of(rid)

    def poll(self):
        if self._done is not None:
            return self._done.returncode
        if self._popen is not None:
            return self._popen.poll()
        return None if not self._server.finished(self._rid) else self.wait().returncode

    def wait(self, timeout: float | None = None) -> subprocess.CompletedProcess:
        if self._done is None:
            if self._popen is not None:
                out, err = self._popen.communicate(timeout=timeout)
                rc = self._popen.returncode
            else:
                if not self._server.events[self._rid].wait(timeout):
                    raise subprocess.TimeoutExpired(self.cmd, timeout)
                rc, out, err = self._server.result(self._rid)
            self._done = subprocess.CompletedProcess(self.cmd, rc, out, err)
        return self._done


def start_snakemake(cwd: Path, *args: str, new_session: bool = False, hide: tuple[str, ...] = ()) -> SnakemakeRun:
    """Start snakemake in ``cwd`` as :func:`run_snakemake` runs it, without waiting for it."""
    cmd, env = _snakemake_cmd(cwd, *args)
    if os.environ.get("OPNAV_TESTS_FORKSERVER", "1") == "0":
        if hide:
            code = (f"import sys; sys.modules.update(dict.fromkeys({list(hide)!r})); "
                    "from snakemake.cli import main; sys.argv[0] = 'snakemake'; main()")
            cmd = [sys.executable, "-c", code, *args]
        popen = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True, start_new_session=new_session)
        return SnakemakeRun(cmd, popen=popen)
    server = _SnakemakeServer.get()
    return SnakemakeRun(cmd, server=server,
                        rid=server.start(Path(cwd), list(args), env, session=new_session, hide=list(hide)))


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
        self.events: dict[int, threading.Event] = {}      # set when a request's child ends
        self.forked: dict[int, threading.Event] = {}      # set when it is forked (pid known)
        self.pids: dict[int, int] = {}
        threading.Thread(target=self._read, daemon=True).start()
        atexit.register(self.close)

    def _read(self):
        for line in self.proc.stdout:
            msg = json.loads(line)
            with self.lock:
                if "pid" in msg:
                    self.pids[msg["id"]] = msg["pid"]
                    self.forked[msg["id"]].set()
                else:
                    self.replies[msg["id"]] = msg["rc"]
                    self.events[msg["id"]].set()
        with self.lock:                      # the server died: wake every waiter
            for ev in (*self.forked.values(), *self.events.values()):
                ev.set()

    def start(self, cwd: Path, args: list[str], env: dict, session: bool = False, hide=()) -> int:
        """Send one request; its id."""
        with self.lock:
            rid = self.next_id
            self.next_id += 1
            self.events[rid], self.forked[rid] = threading.Event(), threading.Event()
            out, err = self.tmp / f"{rid}.out", self.tmp / f"{rid}.err"
            self.proc.stdin.write(json.dumps({"id": rid, "cwd": str(cwd), "argv": args, "env": env,
                                              "stdout": str(out), "stderr": str(err),
                                              "session": session, "hide": list(hide)}) + "\n")
            self.proc.stdin.flush()
        return rid

    def pid_of(self, rid: int) -> int:
        self.forked[rid].wait()
        with self.lock:
            pid = self.pids.get(rid)
        assert pid is not None, "the snakemake server died"
        return pid

    def finished(self, rid: int) -> bool:
        return self.events[rid].is_set()

    def result(self, rid: int) -> tuple[int, str, str]:
        """Wait for request ``rid``: (exit code, stdout, stderr)."""
        self.events[rid].wait()
        with self.lock:
            rc = self.replies.pop(rid, None)
            del self.events[rid], self.forked[rid]
            self.pids.pop(rid, None)
        assert rc is not None, "the snakemake server died"
        out, err = self.tmp / f"{rid}.out", self.tmp / f"{rid}.err"
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


def pytest_itemcollected(item):
    """A test that waits for the shared quick build is slow, marked or not."""
    if _uses_quick_build(item) and item.get_closest_marker("slow") is None:
        item.add_marker(pytest.mark.slow)


#: test files whose tests call the papers' compiled kernels most, by paper, in the order the
#: background warm-up fills the cache (below): run after the others, so the kernels are ready
#: by the time they start (only the order changes, and only for speed)
#: (measured at 2e5e1d9+: each test file alone, the kernel modules it made callable)
KERNEL_FILES = (("test_approach_", "test_custom_estimators"),
                ("test_landing_", "test_timing_", "test_custom_methods", "test_chunk_", "test_cli_overlays",
                 "test_kernel_references", "test_studies"))


def _kernel_rank(item) -> int:
    name = Path(str(item.fspath)).name
    return next((i + 1 for i, prefixes in enumerate(KERNEL_FILES) if name.startswith(prefixes)), 0)


def pytest_collection_modifyitems(config, items):
    """Tests that read the shared quick build run after all others; before them, the test files
    that call the papers' kernels most (KERNEL_FILES), paper A's first (order kept otherwise)."""
    items.sort(key=lambda it: (_uses_quick_build(it), _kernel_rank(it)))


# ------------------------------------------------------------ the kernels, on the second core
# A fresh clone (CI) has an empty numba cache: the first tests that call compiled kernels would
# compile them (about 50 CPU-s) one after the other in this process. A run of many tests instead
# starts one process at collection that warms every kernel module into the cache
# (opnav.core.compiled.warm, module by module, core and paper A first), on the second core while
# the first tests run; a test that needs a module's kernels before they are warm waits for them
# (opnav.core.startup.wait_for_kernels, named by its environment variable) rather than compiling
# them again. On a filled cache it only loads them (a few CPU-s, beside the tests).
WARM_MIN_TESTS = 300
_WARM_CODE = """
import importlib, sys
import opnav.approach, opnav.landing
from opnav.core import compiled
todo = compiled.kernel_modules()
with open(sys.argv[1], "w") as f:
    f.write("todo: " + " ".join(todo) + "\\n")
for m in todo:
    importlib.import_module(m)
    compiled.warm([m])
    with open(sys.argv[1], "a") as f:
        f.write(m + "\\n")
"""
_warm: dict = {}


def pytest_collection_finish(session):
    """Start the background warm-up (above) for a run of at least WARM_MIN_TESTS tests
    (``OPNAV_TESTS_WARM=0``: never)."""
    from opnav.core import startup

    if (len(session.items) < WARM_MIN_TESTS or os.environ.get("OPNAV_TESTS_WARM") == "0"
            or os.environ.get(startup.WARMING_ENV)):
        return
    import opnav

    folder = Path(tempfile.mkdtemp(prefix="opnav-warm-"))
    progress = folder / "done"
    progress.touch()
    env = {k: v for k, v in os.environ.items() if k != startup.WARMING_ENV}
    with open(folder / "warm.log", "w") as log:
        proc = subprocess.Popen([sys.executable, "-c", _WARM_CODE, str(progress)], env=env, stdin=subprocess.DEVNULL,
                                stdout=log, stderr=subprocess.STDOUT)
    _warm.update(proc=proc, folder=folder)
    atexit.register(_stop_warm)      # a session that ends before its summary stops it too
    os.environ[startup.WARMING_ENV] = json.dumps({"pid": proc.pid, "progress": str(progress),
                                                  "package": str(Path(opnav.__file__).parent),
                                                  "cache": os.environ.get("NUMBA_CACHE_DIR", "")})


def _stop_warm() -> dict:
    """End the background warm-up (if still running: what it saved stays in the cache); its CPU-s."""
    proc = _warm.pop("proc", None)
    if proc is None:
        return {}
    from opnav.core import startup

    os.environ.pop(startup.WARMING_ENV, None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.poll() is None:
        proc.terminate()
    proc.wait()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = (_warm["folder"] / "done").read_text().splitlines()[1:]
    shutil.rmtree(_warm.pop("folder"), ignore_errors=True)
    return {"cpu_s": after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, "modules": len(done),
            "rc": proc.returncode}


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
    # a rule with a `message:` prints it instead of its header; the project's messages
    # start "rule NAME (k=v, ...):" so the job still names its rule and wildcards
    for m in re.finditer(r"^Job \d+: rule (\w+)(?: \(([^)]*)\))?:", proc.stdout, re.M):
        jobs.append((m.group(1), dict(kv.split("=", 1) for kv in m.group(2).split(", ")) if m.group(2) else {}))
    return jobs


# ------------------------------------------------------------ hypothesis
# The same examples on every run (CI included): a property test that fails on one
# clone fails on every clone, and a green suite stays green. `HYPOTHESIS_PROFILE=explore
# pytest` draws fresh examples (more of them) to hunt for new counterexamples.
from hypothesis import settings as _hyp_settings  # noqa: E402

_hyp_settings.register_profile("repro", derandomize=True)
_hyp_settings.register_profile("explore", derandomize=False, max_examples=200)
_hyp_settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repro"))


# ------------------------------------------------------------ the fast default run
# `pytest` (README's command) runs the tests not marked slow or cluster (pyproject's
# addopts); `pytest -m slow` runs the slow ones, `pytest -m cluster` the SLURM test. An
# unmarked test must stay fast: one whose call takes more than UNMARKED_LIMIT_CPU_S of
# CPU (this process plus the child processes it waited for), or UNMARKED_LIMIT_WALL_S of
# wall time, fails with a line saying to mark it. CPU, not wall time, is the rule, so a
# loaded machine does not fail a fast test: the wall limit (it catches a test that waits)
# grows with the load average beyond the cores (wall_limit_s). The CPU numba spends compiling kernels in this
# process (opnav.core.startup's compile_s: an empty or stale kernel cache) is taken out of
# both, so the verdict is the same on an empty cache as on a filled one (issue 56 item 5: a
# test that compiled was exempt whole, and a 157.7 s test passed unnoticed); the session's
# compile is reported once at the end instead (pytest_terminal_summary).
UNMARKED_LIMIT_CPU_S = float(os.environ.get("OPNAV_UNMARKED_LIMIT_CPU_S", "5"))
UNMARKED_LIMIT_WALL_S = float(os.environ.get("OPNAV_UNMARKED_LIMIT_WALL_S", "30"))


def _cpu_now() -> float:
    import resource
    import time

    ch = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + ch.ru_utime + ch.ru_stime


def _compile_cpu() -> float:
    """CPU seconds this process spent compiling kernels so far (opnav.core.startup)."""
    startup = sys.modules.get("opnav.core.startup")
    return startup.seconds()["compile_s"] if startup is not None else 0.0


def _warm_wait() -> float:
    """Seconds this process waited for the background warm-up of the kernels so far."""
    startup = sys.modules.get("opnav.core.startup")
    return startup.seconds()["wait_s"] if startup is not None else 0.0


def wall_limit_s() -> float:
    """UNMARKED_LIMIT_WALL_S, times the 1-minute load average per core when above 1 (a test
    gets a share of a core on a shared machine)."""
    return UNMARKED_LIMIT_WALL_S * max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))


def unmarked_too_slow(cpu_s: float, wall_s: float, compile_s: float = 0.0,
                      wall_limit: float | None = None, wait_s: float = 0.0) -> str | None:
    """Why an unmarked test's call is too slow for the default run, or None; ``compile_s``
    (numba compiling kernels during the call) is taken out of both figures, ``wait_s`` (waiting
    for the background warm-up of the kernels) out of the wall time."""
    own_cpu, own_wall = cpu_s - compile_s, wall_s - compile_s - wait_s
    limit = UNMARKED_LIMIT_WALL_S if wall_limit is None else wall_limit
    if own_cpu > UNMARKED_LIMIT_CPU_S:
        return f"took {own_cpu:.1f} CPU-s (> {UNMARKED_LIMIT_CPU_S:g}; kernel compiling aside)"
    if own_wall > limit:
        return f"took {own_wall:.1f} s wall (> {limit:.0f} at this load; kernel compiling aside)"
    return None


_session_compile = {"cpu_s": 0.0, "tests": 0, "waits": []}


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item):
    import time

    if item.get_closest_marker("slow") or item.get_closest_marker("cluster"):
        return (yield)
    cpu0, wall0, comp0, wait0 = _cpu_now(), time.perf_counter(), _compile_cpu(), _warm_wait()
    result = yield
    comp, wait = _compile_cpu() - comp0, _warm_wait() - wait0
    if wait > 0.5:
        _session_compile["waits"].append((wait, item.nodeid))
    if comp:
        _session_compile["cpu_s"] += comp
        _session_compile["tests"] += 1
    why = unmarked_too_slow(_cpu_now() - cpu0, time.perf_counter() - wall0, comp, wall_limit_s(), wait)
    if why:
        pytest.fail(f"unmarked test {why}: mark it @pytest.mark.slow or make it faster", pytrace=False)
    return result


def pytest_terminal_summary(terminalreporter):
    """One line when unmarked tests compiled kernels (an empty or stale cache): how much; one on
    the background warm-up of the kernels, if there was one."""
    warm = _stop_warm()
    if warm:
        terminalreporter.write_line(
            f"kernels warmed beside the tests: {warm['modules']} modules, {warm['cpu_s']:.1f} CPU-s in the "
            f"background process (exit {warm['rc']}); the tests waited {_warm_wait():.1f} s for it"
            + "".join(f"; {w:.1f} s in {n}" for w, n in sorted(_session_compile["waits"], reverse=True)[:3]))
    if _session_compile["tests"]:
        terminalreporter.write_line(
            f"numba compiled kernels in {_session_compile['tests']} unmarked tests: "
            f"{_session_compile['cpu_s']:.1f} CPU-s (an empty or stale kernel cache; the next run "
            "loads them; the slow-test guard leaves it out)")
