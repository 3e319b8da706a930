"""Build the manuscript PDF with latexmk, reproducibly (fixed SOURCE_DATE_EPOCH)."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from opnav.core.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_pdf", argv=sys.argv[1:])

with script_context(snakemake) as log:
    paper_dir = Path(snakemake.params.paper_dir).resolve()
    build = Path(snakemake.params.build).resolve()
    out = Path(snakemake.output[0]).resolve()
    results_rel = os.path.relpath(out.parent.parent, paper_dir)
    env = dict(os.environ, SOURCE_DATE_EPOCH="0", FORCE_SOURCE_DATE="1", TZ="UTC")
    shutil.rmtree(build, ignore_errors=True)
    cmd = ["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", f"-outdir={build}",
           f"-usepretex=\\def\\resultsdir{{{Path(results_rel).as_posix()}}}", "main.tex"]
    log.info("running %s in %s", " ".join(cmd), paper_dir)
    proc = subprocess.run(cmd, cwd=paper_dir, env=env, capture_output=True, text=True)
    log.info(proc.stdout[-20000:])
    if proc.returncode != 0:
        raise RuntimeError(f"latexmk failed (exit {proc.returncode}); see {build}/main.log")
    missing = sorted(set(re.findall(r"opnav-missing-macro (\w+)", (build / "main.log").read_text(errors="replace"))))
    if missing:
        log.warning("opnav-missing-macro: the manuscript quotes numbers no rule wrote: %s", ", ".join(missing))
    shutil.copyfile(build / "main.pdf", out)
