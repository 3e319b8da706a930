"""Build the manuscript PDF with latexmk, reproducibly (fixed SOURCE_DATE_EPOCH)."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from opnav.core.snakeio import mock_snakemake, script_context
from opnav.report import print_size

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
    tex_log = (build / "main.log").read_text(errors="replace")
    missing = sorted(set(re.findall(r"opnav-missing-macro (\w+)", tex_log)))
    if missing:
        log.warning("opnav-missing-macro: the manuscript quotes numbers no rule wrote: %s", ", ".join(missing))
    # every table's printed font size (paper/print-size.tex writes it as the table is typeset)
    sizes = print_size.table_sizes(tex_log)
    log.info("tables printed at (pt): %s", ", ".join(f"{s.table}: {s.pt if s.pt is None else round(s.pt, 1)}"
                                                      for s in sizes))
    for s in print_size.small_tables(sizes):
        log.warning("opnav-small-table: Table %s is printed at %.1f pt, under %g pt", s.table, s.pt,
                    print_size.MIN_TABLE_PT)
    shutil.copyfile(build / "main.pdf", out)
