"""The build's job server: every workflow job's libraries imported once per build, not once per job.

Each Snakemake ``script:`` job is a fresh interpreter that imports numpy, scipy, pandas,
matplotlib and numba before its own work: 0.4-1.0 CPU-s a job, most of a small job's cost
(docs/dev/performance-log.md). A local build (the Snakefile's ``onstart``, :func:`start`) starts
one server process that imports those libraries (:func:`_preload`: installed libraries only,
never ``opnav``, so a job always runs the checkout's own code) and then waits. Each workflow
script begins with :func:`delegate`: the job's process (the *client*: the interpreter and
Snakemake's preamble, about 0.25 CPU-s) sends the server its script, command line, working
directory, environment, ``sys.path`` and its standard streams (file descriptors), and the
server forks a child that becomes the job: it takes the job's streams, directory,
environment and path and runs the same script file (Snakemake's preamble included) as
``__main__``. The client waits and leaves with the child's exit status. The job runs the same
code on the same inputs as in a fresh interpreter: only the libraries' import is shared.

Everything else is as before: where no server is up (a script run by hand, a cluster job, a
build of a few jobs, ``OPNAV_JOB_SERVER=0``, a job whose BLAS thread count is not the server's
one), :func:`delegate` returns at once and the script runs in its own process. The child ends
when its client ends (Snakemake stopping a job kills the client: the child sees its connection
close) and when the server ends (parent-death signal); the server ends with the build
(:func:`stop`, or the parent-death signal if Snakemake is killed). A job's log keeps its whole
CPU (``job resources: cpu_s=...``: the child's, plus the client's before it delegated, passed
along); its peak memory counts the server's pages it shares (``job_server=1`` on that line).
Snakemake's ``benchmark:`` files time the client only: a job's own CPU is in its log
(``benchmarks/job_costs.py``).

Run as ``python jobserver.py SOCKET`` (the file, not ``-m``: the server imports nothing of
``opnav``).
"""

from __future__ import annotations

import json
import os
import socket
import sys

#: the environment variable naming the server's socket to a build's jobs; ``0`` turns it off
ENV = "OPNAV_JOB_SERVER"
#: the server's process id, beside :data:`ENV` (a job waits for a server that is still starting)
PID_ENV = "OPNAV_JOB_SERVER_PID"
#: the client's user and system CPU-s before it delegated (``"user,sys"``), in the child's
#: environment: :func:`client_cpu` (the job's start-up and resource line count them)
CLIENT_CPU_ENV = "OPNAV_JOB_CLIENT_CPU_S"
#: thread-count variables Snakemake sets per job (its ``threads``): the server imports numpy
#: with one thread, so only a job of one thread is delegated
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "VECLIB_MAXIMUM_THREADS",
               "NUMEXPR_NUM_THREADS", "GOTO_NUM_THREADS")
#: a build with fewer jobs to run than this starts no server (its imports, about 2 CPU-s, cost
#: what about four jobs save)
MIN_JOBS = 6

_server: dict = {}


# ---------------------------------------------------------------- the client (a workflow job)
def delegate(any_threads: bool = False) -> None:
    """Called first by every workflow script. In a job of a build whose server is up, send the
    job to the server, wait for it and leave with its exit status (never returns); otherwise
    (and in the server's child itself) return at once, and the script runs here.

    A job of several threads runs in its own process (the server's numpy has one BLAS thread),
    unless ``any_threads``: a job that takes every core only to run alone and whose own numerics
    do not use them (the timing replays: their timed processes are fresh, started by the job)."""
    path = os.environ.get(ENV)
    main = sys.modules.get("__main__")
    smk = getattr(main, "snakemake", None)
    if not path or path == "0" or smk is None or not type(smk).__module__.startswith("snakemake"):
        return
    if not any_threads and any(os.environ.get(v, "1") != "1" for v in THREAD_VARS):
        return                                   # a job of several threads: its own process
    import resource
    import signal

    if not _wait_ready(path):
        return
    try:
        conn = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        conn.connect(path)
        me = resource.getrusage(resource.RUSAGE_SELF)
        # the file this interpreter runs: Snakemake's copy of the script with its preamble
        # (the preamble sets __file__ to the original script's path)
        req = {"script": os.path.abspath(sys.argv[0]), "argv": sys.argv, "cwd": os.getcwd(),
               "env": dict(os.environ), "path": sys.path, "cpu": [me.ru_utime, me.ru_stime],
               "sigint_ignored": signal.getsignal(signal.SIGINT) is signal.SIG_IGN}
        _send(conn, req, [0, 1, 2])
        reply = _recv_line(conn)
    except OSError:
        return                                   # no server (gone, or not started yet): run here
    if not reply or "pid" not in reply:
        return
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    try:
        done = _recv_line(conn)                  # the child's exit status, or nothing: the server died
    except KeyboardInterrupt:                    # Ctrl-C: the child has it too (its traceback is in the
        done = {"rc": -signal.SIGINT}            # job's log); this process ends by it, quietly
    rc = int(done["rc"]) if done and "rc" in done else 1
    if rc < 0:                                   # the child was killed: so is the job
        signal.signal(-rc, signal.SIG_DFL)
        os.kill(os.getpid(), -rc)
    os._exit(rc if rc >= 0 else 128 - rc)


def _wait_ready(path: str, limit_s: float = 60.0) -> bool:
    """Whether the server at ``path`` listens: its socket appears once it has imported the
    libraries (a few seconds after the build starts); until then, while its process lives
    (:data:`PID_ENV`), wait (the build's first jobs would otherwise import them themselves)."""
    import time

    pid = os.environ.get(PID_ENV, "")
    deadline = time.monotonic() + limit_s
    while not os.path.exists(path):
        if not _alive(pid) or time.monotonic() > deadline:
            return False                         # no server process: run here
        time.sleep(0.05)
    return True


def _alive(pid: str) -> bool:
    """Whether process ``pid`` runs (not ended, not a zombie)."""
    try:
        os.kill(int(pid), 0)
    except (ValueError, ProcessLookupError, PermissionError):
        return False
    try:
        with open(f"/proc/{int(pid)}/stat", "rb") as f:
            return f.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True


#: read once, when the job's script first imports this module in the server's child, and taken
#: out of the environment: the job's own subprocesses (the timing replays) are not the job
_CLIENT_CPU = os.environ.pop(CLIENT_CPU_ENV, "")


def client_cpu() -> tuple[float, float]:
    """(user, system) CPU-s the job's client process spent before it delegated to this process
    (0, 0 in a job that runs in its own process)."""
    text = _CLIENT_CPU
    try:
        user, sys_ = (float(x) for x in text.split(","))
    except ValueError:
        return 0.0, 0.0
    return user, sys_


def _send(conn: socket.socket, obj: dict, fds: list[int]) -> None:
    data = json.dumps(obj).encode()
    socket.send_fds(conn, [len(data).to_bytes(8, "little"), data], fds)


def _recv_line(conn: socket.socket) -> dict | None:
    buf = b""
    while not buf.endswith(b"\n"):
        chunk = conn.recv(4096)
        if not chunk:
            return None
        buf += chunk
    return json.loads(buf)


# ---------------------------------------------------------------- the build's side
def start(workflow) -> str | None:
    """``onstart``: start the server for a local build of at least :data:`MIN_JOBS` script jobs
    (unless ``OPNAV_JOB_SERVER=0``) and name its socket to the jobs (:data:`ENV`); the socket
    path, or None. It does not wait for the server: a job that starts before it is ready runs
    in its own process."""
    import subprocess
    import tempfile

    if os.environ.get(ENV) == "0" or _server:
        return None
    if not getattr(workflow, "local_exec", False):
        return None
    try:
        n = sum(1 for j in workflow.dag.needrun_jobs() if getattr(j.rule, "script", None))
    except Exception:                            # noqa: BLE001 - no count: no server
        return None
    if n < MIN_JOBS:
        return None
    folder = tempfile.mkdtemp(prefix="opnav-jobs-")
    path = os.path.join(folder, "socket")
    env = dict(os.environ, **dict.fromkeys(THREAD_VARS, "1"))
    env.pop(ENV, None)
    proc = subprocess.Popen([sys.executable, __file__, path], env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, start_new_session=False)
    _server.update(proc=proc, folder=folder, path=path)
    os.environ[ENV] = path                       # inherited by every job started from now on
    os.environ[PID_ENV] = str(proc.pid)
    return path


def stop() -> None:
    """``onsuccess`` / ``onerror``: end the server (its CPU is then counted with the build's)."""
    import shutil
    import signal

    proc = _server.pop("proc", None)
    if proc is None:
        return
    os.environ.pop(ENV, None)
    os.environ.pop(PID_ENV, None)
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except Exception:                        # noqa: BLE001 - ending anyway
            proc.kill()
            proc.wait()
    shutil.rmtree(_server.pop("folder"), ignore_errors=True)
    _server.clear()


# ---------------------------------------------------------------- the server
def _die_with_parent(parent: int) -> None:
    """SIGTERM to this process when ``parent`` dies (Linux; elsewhere nothing)."""
    import signal

    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGTERM), 0, 0, 0)   # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:
        os._exit(1)


def _preload() -> None:
    """Import the installed libraries the jobs import (the project's dependencies; nothing of
    ``opnav``), set numba and matplotlib up as a job's first use would, and freeze them."""
    import casadi  # noqa: F401
    import jsonschema  # noqa: F401
    import matplotlib
    import numba
    import numba.np.arraymath  # noqa: F401
    import numba.np.linalg  # noqa: F401
    import numpy  # noqa: F401
    import pandas  # noqa: F401
    import pandas.io.formats.csvs  # noqa: F401  (DataFrame.to_csv)
    import pandas.io.formats.string  # noqa: F401
    import pandas.io.formats.style  # noqa: F401  (DataFrame.to_latex)
    import PIL.Image
    import scipy.integrate  # noqa: F401
    import scipy.interpolate  # noqa: F401
    import scipy.linalg  # noqa: F401
    import scipy.optimize  # noqa: F401
    import scipy.spatial  # noqa: F401
    import scipy.special  # noqa: F401
    import scipy.stats  # noqa: F401
    import snakemake.io  # noqa: F401  (the script preamble's)
    import snakemake.iocontainers  # noqa: F401
    import snakemake.logging  # noqa: F401
    import snakemake.script  # noqa: F401
    import tabulate  # noqa: F401  (DataFrame.to_markdown; wcwidth)
    import threadpoolctl  # noqa: F401
    import yaml  # noqa: F401

    matplotlib.use("Agg")
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.backends.backend_pdf  # noqa: F401
    import matplotlib.pyplot  # noqa: F401

    # numba's typing and target set up as a job's first kernel would (about 0.15 CPU-s a kernel
    # job): one tiny function compiled, not cached; and matplotlib's font list read once
    numba.njit(lambda x: x + 1.0)(1.0)
    import matplotlib.font_manager

    matplotlib.font_manager.fontManager  # noqa: B018
    PIL.Image.init()                             # the image plugins a PNG save registers
    import fontTools.subset  # noqa: F401  (the PDF backend's font subsetting)
    import resource  # noqa: F401  (the jobs' resource line)
    import runpy  # noqa: F401
    import gc

    gc.collect()
    gc.freeze()                                  # the children's collector leaves these (and their pages) alone


def _child(listener: socket.socket, conn: socket.socket, req: dict, fds: list[int], server: int) -> None:
    """In the forked child: become the job (module docstring); never returns."""
    import signal
    import threading

    code = 1
    try:
        signal.set_wakeup_fd(-1)
        for sig in (signal.SIGCHLD, signal.SIGTERM):
            signal.signal(sig, signal.SIG_DFL)
        # SIGINT as the job's own interpreter has it: KeyboardInterrupt, or ignored where the
        # build was started ignoring it (a background job: runguard keeps it so)
        signal.signal(signal.SIGINT, signal.SIG_IGN if req.get("sigint_ignored") else signal.default_int_handler)
        _die_with_parent(server)
        listener.close()
        for target, fd in zip((0, 1, 2), fds):
            os.dup2(fd, target)
            os.close(fd)

        def watch():                             # the client gone (Snakemake stopped the job): end
            try:
                while conn.recv(1):
                    pass
            except OSError:
                pass
            os.kill(os.getpid(), signal.SIGTERM)

        threading.Thread(target=watch, daemon=True).start()
        os.chdir(req["cwd"])
        env = {k: v for k, v in req["env"].items() if k not in (ENV, PID_ENV)}
        env[CLIENT_CPU_ENV] = ",".join(f"{float(x):.6f}" for x in req["cpu"])
        os.environ.clear()
        os.environ.update(env)
        import tempfile

        tempfile.tempdir = None                  # the job's TMPDIR
        sys.argv = list(req["argv"])
        sys.path[:] = list(req["path"])
        import runpy

        try:
            runpy.run_path(req["script"], run_name="__main__")
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            if exc.code is not None and not isinstance(exc.code, int):
                print(exc.code, file=sys.stderr)
    except BaseException:                        # noqa: BLE001 - as the interpreter would: traceback, 1
        import traceback

        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def serve(path: str) -> None:
    """The server's loop: preload, listen on ``path``, fork a child per job, send each client
    its child's pid and then its exit status."""
    import select
    import signal

    parent = os.getppid()
    _die_with_parent(parent)
    _preload()
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(path + ".new")
    listener.listen(64)
    os.rename(path + ".new", path)               # the path appears when the server listens
    wake_r, wake_w = os.pipe()
    os.set_blocking(wake_w, False)
    signal.set_wakeup_fd(wake_w)
    signal.signal(signal.SIGCHLD, lambda *a: None)
    stopping = []
    signal.signal(signal.SIGTERM, lambda *a: stopping.append(1))
    # a Ctrl-C reaches the build's process group, this process included: the jobs (its children,
    # in the same group) get it as in their own interpreters; the server ends with the build
    # (SIGTERM from opnav.core.runguard, stop(), or the parent-death signal)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    running: dict[int, socket.socket] = {}
    while not stopping:
        ready, _, _ = select.select([listener, wake_r], [], [], 1.0)
        if wake_r in ready:
            os.read(wake_r, 4096)
        if listener in ready:
            conn, _ = listener.accept()
            try:
                head, fds, _, _ = socket.recv_fds(conn, 8, 3)
                size = int.from_bytes(head, "little")
                data = b""
                while len(data) < size:
                    chunk = conn.recv(size - len(data))
                    if not chunk:
                        raise OSError("client gone")
                    data += chunk
                req = json.loads(data)
            except (OSError, ValueError):
                conn.close()
                continue
            for stream in (sys.stdout, sys.stderr):
                stream.flush()
            pid = os.fork()
            if pid == 0:
                _child(listener, conn, req, fds, os.getppid())
            for fd in fds:
                os.close(fd)
            running[pid] = conn
            try:
                conn.sendall((json.dumps({"pid": pid}) + "\n").encode())
            except OSError:
                pass
        while running:
            pid, status = os.waitpid(-1, os.WNOHANG)
            if pid == 0:
                break
            conn = running.pop(pid, None)
            if conn is not None:
                try:
                    conn.sendall((json.dumps({"rc": os.waitstatus_to_exitcode(status)}) + "\n").encode())
                except OSError:
                    pass
                conn.close()
    listener.close()
    for pid in running:                          # jobs still running when the build ends: stop them
        try:
            os.kill(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
    for pid in list(running):
        os.waitpid(pid, 0)


if __name__ == "__main__":
    serve(sys.argv[1])
