"""How a build stops: on a signal, at once and saying so; never waiting on a cluster it cannot see.

Snakemake 9.27 on its own (measured, issue 57): SIGTERM to ``snakemake --cores 2`` prints
"Will exit after finishing currently running jobs", waits for them (a Monte-Carlo job:
minutes), then ends with "At least one job did not complete successfully" although none
failed; after SIGKILL its jobs run on as orphans. With the SLURM executor and no status
command it submits, then waits silently for ever, and SIGTERM and SIGINT do not end it.

The Snakefile's ``onstart`` calls :func:`guard` and its ``onerror`` :func:`interrupted_exit`:

* :func:`slurm_problem`: with the SLURM executor, the commands it needs (``sbatch``,
  ``scancel``, ``sinfo`` and the job-status command, ``squeue`` or ``sacct``) must be on
  PATH, else one line and exit 1 before anything is submitted;
* SIGTERM, SIGINT and SIGHUP (each unless ignored: ``nohup``'s SIGHUP stays ignored): one line ("interrupted by SIGTERM: stopping N running
  jobs"), the running jobs stopped (SIGTERM to every process the build started, then the
  executor's own cancel: ``scancel`` on a cluster), and the build ends within
  :data:`GRACE_S` s whatever the executor does: then the working directory's lock is
  released and the process leaves with 128 + the signal's number. In ``onerror`` the build
  says it was interrupted, not that a job failed, and leaves with the same code;
* every job process (:func:`stop_with_parent`, called by ``script_context``) ends when the
  process that started it dies, even by SIGKILL: the kernel's parent-death signal on Linux,
  a one-second watch of the parent elsewhere.

Jobs stopped halfway keep Snakemake's incomplete markers: the next run redoes them
(``rerun-incomplete: true`` in both profiles).
"""

from __future__ import annotations

import logging
import os
import shutil
import signal
import sys
import threading
import time

__all__ = ["guard", "slurm_problem", "interrupted_exit", "stop_with_parent", "GRACE_S"]

#: Seconds from the signal to the process's end at the latest.
GRACE_S = 8.0

_state: dict = {"signal": None, "jobs": 0}

#: The environment variable naming the build's process (``pid@host``) to its jobs.
BUILD_ENV = "OPNAV_BUILD_PROCESS"


def _host() -> str:
    import socket

    return socket.gethostname()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def slurm_problem(workflow) -> str | None:
    """The line refusing a SLURM run whose commands are missing here (None where the executor
    is not SLURM or every command is found)."""
    plugin = getattr(workflow, "executor_plugin", None)
    if getattr(plugin, "name", None) != "slurm":
        return None
    settings = getattr(workflow, "executor_settings", None)
    status = getattr(settings, "status_command", None) or "squeue"
    missing = [c for c in ("sbatch", status, "scancel", "sinfo") if shutil.which(c) is None]
    if not missing:
        return None
    what = {"sbatch": "submits the jobs", "scancel": "cancels them when the run stops",
            status: f"tells when a job ends (slurm-status-command: {status})",
            "sinfo": "names the default partition"}
    return (f"opnav: the SLURM executor needs {', '.join(repr(c) for c in missing)} on PATH and "
            f"{'it is' if len(missing) == 1 else 'they are'} missing here ({'; '.join(f'{c} {what[c]}' for c in missing)}): "
            "nothing was submitted. Run on a node with the SLURM client commands (docs/cluster.md), or locally "
            "without --workflow-profile profiles/slurm")


def guard(workflow) -> None:
    """``onstart``: refuse a SLURM run that could not see its jobs (:func:`slurm_problem`),
    then install the signal handlers (module docstring)."""
    problem = slurm_problem(workflow)
    if problem:
        raise SystemExit(problem)
    if threading.current_thread() is not threading.main_thread():   # pragma: no cover
        return
    main_pid = os.getpid()
    os.environ[BUILD_ENV] = f"{main_pid}@{_host()}"     # inherited by every job it starts

    def handler(signum, frame):
        if _state["signal"] is not None or os.getpid() != main_pid:
            return                                       # a second signal: the first one is handled
        name = signal.Signals(signum).name
        _state["signal"] = signum
        kids = _descendants(main_pid)
        _state["jobs"] = len(kids)
        print(f"opnav: interrupted by {name}: stopping {len(kids)} running process(es) of this build; "
              "run the same command again to resume (stopped jobs are redone)", file=sys.stderr, flush=True)
        # the jobs stopped here are not failures: Snakemake's error records of them are dropped
        logging.getLogger("snakemake.logging").addFilter(_quiet_after_signal)
        for pid in kids:
            _kill(pid, signal.SIGTERM)
        threading.Thread(target=_deadline, args=(workflow, main_pid, signum), daemon=True).start()
        raise KeyboardInterrupt                           # the scheduler cancels through its executor

    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        if signal.getsignal(sig) is not signal.SIG_IGN:     # nohup's SIGHUP, a background & SIGINT: kept
            signal.signal(sig, handler)


def _quiet_after_signal(record) -> bool:
    """A logging filter: after the signal, no error records (the stopped jobs' 'Error in rule',
    their killed commands' exceptions), and no 'Terminating processes' line."""
    return record.levelno < logging.ERROR and "Terminating processes" not in str(record.msg)


def interrupted_exit() -> None:
    """``onerror``: after a signal, one line saying so and the exit code 128 + signal
    (Snakemake would say "At least one job did not complete successfully")."""
    signum = _state["signal"]
    if signum is None:
        return
    print(f"opnav: the build was interrupted by {signal.Signals(signum).name} (no job failed); "
          "run the same command again to resume", file=sys.stderr, flush=True)
    raise SystemExit(128 + signum)


def _deadline(workflow, main_pid: int, signum: int) -> None:
    """After :data:`GRACE_S` s: SIGKILL to what is left of the build's processes, the lock
    released, and the process ended (the SLURM executor's shutdown waits on its status
    thread, which may sleep for minutes)."""
    time.sleep(GRACE_S / 2)
    for pid in _descendants(main_pid):
        _kill(pid, signal.SIGKILL)
    time.sleep(GRACE_S / 2)
    try:
        workflow.persistence.unlock()
    except Exception:                                     # noqa: BLE001 - leaving anyway
        pass
    print(f"opnav: the build was interrupted by {signal.Signals(signum).name} (no job failed); stopped after "
          f"{GRACE_S:g} s. Run the same command again to resume", file=sys.stderr, flush=True)
    os._exit(128 + signum)


def _kill(pid: int, sig: int) -> None:
    try:
        os.kill(pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def _descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (read from /proc; empty where there is none)."""
    children: dict[int, list[int]] = {}
    try:
        entries = os.listdir("/proc")
    except OSError:
        return []
    for e in entries:
        if not e.isdigit():
            continue
        try:
            with open(f"/proc/{e}/stat", "rb") as f:
                ppid = int(f.read().rsplit(b")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(e))
    out, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.append(c)
            todo.append(c)
    return out


def stop_with_parent() -> None:
    """End this job process when the process that started it (Snakemake) dies, even by
    SIGKILL: PR_SET_PDEATHSIG on Linux (the kernel sends SIGTERM), a daemon thread checking
    the parent every second elsewhere. A job whose build died while it was still starting
    (before this call) ends at once: :func:`guard` leaves the build's ``pid@host`` in
    :data:`BUILD_ENV`, and that process is gone."""
    parent = os.getppid()
    build = os.environ.get(BUILD_ENV, "")
    pid, _, host = build.partition("@")
    if pid.isdigit() and host == _host() and parent != int(pid) and not _alive(int(pid)):
        os.kill(os.getpid(), signal.SIGTERM)              # started by a build that is gone
        return
    if parent <= 1:
        return
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(1, int(signal.SIGTERM), 0, 0, 0) == 0:      # PR_SET_PDEATHSIG
                if os.getppid() != parent:                                # died before the call
                    os.kill(os.getpid(), signal.SIGTERM)
                return
        except (OSError, AttributeError):
            pass

    def watch():
        while True:
            time.sleep(1.0)
            if os.getppid() != parent:
                os.kill(os.getpid(), signal.SIGTERM)
                return

    threading.Thread(target=watch, daemon=True, name="opnav-stop-with-parent").start()
