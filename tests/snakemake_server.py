"""A fork server for the tests' ``snakemake`` runs (tests/conftest.py, run_snakemake).

Importing Snakemake's command line and collecting its plugins costs about 1.1 CPU-s
of the 2.4 CPU-s of a dry run, in every one of the suite's ~25 snakemake runs. This
process pays it once: it imports ``snakemake.cli``, the plugin registries and the
installed libraries a run goes on to import (``PRELOAD``; nothing of the workflow: no
``opnav``), then forks one child per request, which
runs ``snakemake.cli.main()`` with the request's argv, working directory,
environment and ``sys.path`` (what ``python -m snakemake`` in that directory with
that environment would have), its stdout and stderr sent to the request's files.
The child is the same code on the same arguments as ``python -m snakemake``; only
the import is shared.

Protocol (one JSON object a line): request on stdin
``{"id", "cwd", "argv", "env", "stdout", "stderr"}`` and optionally ``"session": true``
(the child leads a new session and process group, as ``Popen(start_new_session=True)``,
so that a test can signal it and its jobs) and ``"hide": [module, ...]`` (those modules
set to None in ``sys.modules``: ``import`` fails as if they were not installed); replies
on stdout ``{"id", "pid"}`` when the child is forked and ``{"id", "rc"}`` when it ends
(children run concurrently).
"""

import json
import os
import select
import signal
import sys

# sys.path of this process without what PYTHONPATH and the script's folder put there:
# a child rebuilds its own in front of it, as a fresh interpreter would.
_OWN = {os.path.abspath(p) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p}
_OWN.add(os.path.dirname(os.path.abspath(__file__)))
BASE_PATH = [p for p in sys.path if p and os.path.abspath(p) not in _OWN]

from pathlib import Path  # noqa: E402

import importlib  # noqa: E402
import importlib.util  # noqa: E402

import snakemake.cli  # noqa: E402
import snakemake.workflow  # noqa: E402
from snakemake_interface_executor_plugins.registry import ExecutorPluginRegistry  # noqa: E402
from snakemake_interface_logger_plugins.registry import LoggerPluginRegistry  # noqa: E402
from snakemake_interface_report_plugins.registry import ReportPluginRegistry  # noqa: E402
from snakemake_interface_storage_plugins.registry import StoragePluginRegistry  # noqa: E402

# what `python -m snakemake` has as sys.argv[0] (importing it would run snakemake)
MAIN = importlib.util.find_spec("snakemake.__main__").origin

for _registry in (ExecutorPluginRegistry, StoragePluginRegistry, ReportPluginRegistry, LoggerPluginRegistry):
    _registry()  # singletons: collected once, inherited by every child

#: Installed libraries every run imports after main() starts (Snakemake's lazy imports:
#: smart_open to read the Snakefile, the report modules; and what parsing the Snakefile
#: imports through ``opnav``: jsonschema, scipy, casadi), about 0.45 CPU-s a run, paid
#: here once. Never anything of the workflow (``opnav`` is each request's own copy under
#: its cwd): only site-packages, which every request shares. numpy (with the
#: OPENBLAS_NUM_THREADS=1 of tests/conftest.py) and pandas are already imported by
#: snakemake.cli above.
PRELOAD = ("smart_open", "snakemake.report.html_reporter", "jsonschema",
           "scipy.linalg", "scipy.spatial", "scipy.special", "casadi")
for _name in PRELOAD:
    try:
        importlib.import_module(_name)
    except ImportError:  # not installed: the run imports (or misses) it as before
        pass


def _child(req: dict) -> None:
    """In the forked child: become ``python -m snakemake`` of the request; never returns."""
    code = 1
    try:
        if req.get("session"):
            os.setsid()
            # a test signals this session as a terminal's Ctrl-C would: SIGINT raises
            # KeyboardInterrupt here and in the jobs, even where the test run inherited it
            # ignored (a shell's background job, nohup: ignored signals survive exec)
            signal.signal(signal.SIGINT, signal.default_int_handler)
        for name in req.get("hide", ()):
            sys.modules[name] = None
        os.chdir(req["cwd"])
        os.environ.clear()
        os.environ.update(req["env"])
        extra = [p for p in req["env"].get("PYTHONPATH", "").split(os.pathsep) if p]
        sys.path[:] = [req["cwd"], *extra, *BASE_PATH]
        for fd, path in ((1, req["stdout"]), (2, req["stderr"])):
            f = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
            os.dup2(f, fd)
            os.close(f)
        sys.stdin = open(os.devnull)
        sys.argv = [MAIN, *req["argv"]]
        # the one import-time value of the working directory (the log header's "Run directory")
        snakemake.workflow.Workflow._rundir = str(Path.cwd().absolute())
        try:
            snakemake.cli.main()
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            if exc.code is not None and not isinstance(exc.code, int):
                print(exc.code, file=sys.stderr)
    except BaseException:
        import traceback

        traceback.print_exc()
        code = 1
    finally:
        try:
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os._exit(code)


def main() -> None:
    running = {}  # pid -> request id
    buf = b""
    stdin = sys.stdin.buffer.raw
    open_in = True
    print(json.dumps({"ready": os.getpid()}), flush=True)
    while open_in or running:
        if open_in:
            ready, _, _ = select.select([stdin], [], [], 0.02)
            if ready:
                chunk = os.read(stdin.fileno(), 65536)
                if not chunk:
                    open_in = False
                buf += chunk
                while b"\n" in buf:
                    line, buf = buf.split(b"\n", 1)
                    req = json.loads(line)
                    pid = os.fork()
                    if pid == 0:
                        _child(req)
                    running[pid] = req["id"]
                    print(json.dumps({"id": req["id"], "pid": pid}), flush=True)
        else:
            select.select([], [], [], 0.02)
        while running:
            pid, status = os.waitpid(-1, os.WNOHANG)
            if pid == 0:
                break
            rid = running.pop(pid, None)
            if rid is not None:
                print(json.dumps({"id": rid, "rc": os.waitstatus_to_exitcode(status)}), flush=True)


if __name__ == "__main__":
    main()
