"""Figure/table floats for the manuscript, one file per paper.

Tables too wide for a page (ids in opnav.report.manuscript.COMPACT_VIEWS) are shown
through a compact view computed from their CSV, written under compact/.
"""

import sys
from pathlib import Path


from opnav.report.manuscript import COMPACT_VIEWS, float_block, output_id, table1_grouped_latex
from opnav.core.snakeio import load_table, mock_snakemake, script_context
from opnav.core.tables import atomic_write_text, write_table

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("paper_floats", argv=sys.argv[1:])

with script_context(snakemake) as log:
    compact_dir = Path(snakemake.output.compact)
    compact_dir.mkdir(parents=True, exist_ok=True)
    for part in ("approach", "landing"):
        paths = []
        for p in map(Path, snakemake.input[part]):
            view = COMPACT_VIEWS.get(output_id(p)) if p.suffix == ".tex" else None
            if view is None:
                paths.append(p)
                continue
            for suffix, df in view(load_table(p.with_suffix(".csv"))):
                stem = f"{p.stem}_{suffix}" if suffix else p.stem
                out = compact_dir / f"{stem}.tex"
                write_table(df, [out])
                paths.append(out)
        text = float_block(paths, snakemake.params.captions_dir, relative_to=snakemake.params.paper_dir)
        atomic_write_text(snakemake.output[part], text or "% no outputs yet\n")
        log.info("%s: %d floats", part, len(paths))
    a_t1 = list(snakemake.input.a_table1) if "a_table1" in snakemake.input.keys() else []
    atomic_write_text(snakemake.output.table1, table1_grouped_latex(load_table(a_t1[0])) if a_t1
                      else "% paper A Table 1 not built\n")
