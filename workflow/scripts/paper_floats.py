"""Figure/table floats for the manuscript, one file per paper.

Every table is printed from its CSV, under compact/: through a compact view where one is
defined (opnav.report.manuscript.COMPACT_VIEWS), with wrapped headers and, when much wider
than long, transposed (opnav.report.manuscript.legible_latex).
"""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys
from pathlib import Path


from opnav.report.manuscript import COMPACT_VIEWS, float_block, legible_latex, output_id, table1_grouped_latex
from opnav.core.snakeio import load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_floats", argv=sys.argv[1:])

with script_context(snakemake) as log:
    compact_dir = Path(snakemake.output.compact)
    compact_dir.mkdir(parents=True, exist_ok=True)
    for part in ("approach", "landing"):
        paths, captions = [], {}
        for p in map(Path, snakemake.input[part]):
            # the caption rendered for this output's job (keyed by its workflow path; a run by
            # hand gives absolute paths)
            cap = next((c for k, c in snakemake.params.captions.items() if p == Path(k) or p.match(k)), None)
            if cap is not None:
                captions[str(p)] = cap
            if p.suffix != ".tex" or not p.with_suffix(".csv").is_file():
                paths.append(p)
                continue
            # every table from its CSV: the compact view of a wide one, then legible_latex
            view = COMPACT_VIEWS.get(output_id(p), lambda df: [("", df)])
            for suffix, df in view(load_table(p.with_suffix(".csv"))):
                stem = f"{p.stem}_{suffix}" if suffix else p.stem
                out = compact_dir / f"{stem}.tex"
                atomic_write_text(out, legible_latex(df))
                paths.append(out)
                if str(p) in captions:  # the table's caption, rendered for its job
                    captions[str(out)] = captions[str(p)]
        text = float_block(paths, snakemake.params.captions_dir, relative_to=snakemake.params.paper_dir,
                           captions=captions)
        atomic_write_text(snakemake.output[part], text or "% no outputs yet\n")
        log.info("%s: %d floats", part, len(paths))
    a_t1 = list(snakemake.input.a_table1) if "a_table1" in snakemake.input.keys() else []
    atomic_write_text(snakemake.output.table1, table1_grouped_latex(load_table(a_t1[0])) if a_t1
                      else "% paper A Table 1 not built\n")
