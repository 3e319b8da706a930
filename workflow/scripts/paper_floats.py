"""Figure/table floats for the manuscript, one file per paper."""

from opnav.manuscript import float_block
from opnav.snakeio import script_context
from opnav.tables import atomic_write_text

with script_context(snakemake) as log:
    for part in ("approach", "landing"):
        text = float_block(snakemake.input[part], snakemake.params.captions_dir,
                           relative_to=snakemake.params.paper_dir)
        atomic_write_text(snakemake.output[part], text or "% no outputs yet\n")
        log.info("%s: %d floats", part, len(snakemake.input[part]))
