"""A-P1 table and summary: the peer UKF beside the EM-EKF, augmented EKF, batch ML and the CRLB."""

from opnav.core.jobserver import delegate

delegate()  # in a local build the job runs in the build's job server (opnav.core.jobserver); by hand, here

import sys

from opnav.approach import peers
from opnav.core.snakeio import load_pickle, mock_snakemake, script_context
from opnav.core.tables import write_json, write_table
from opnav.report.approach import text as words

if "snakemake" not in globals():  # by hand, as the real job (workflow/scripts/README.md)
    snakemake = mock_snakemake("approach_peer_tables", argv=sys.argv[1:])


def load(paths):
    """The records of the pickles: a Monte-Carlo list, an A-X2 job's ``results``, a peer variant."""
    out = []
    for p in paths:
        d = load_pickle(p)
        out.extend(d if isinstance(d, list) else d["results"] if isinstance(d, dict) else [d])
    return out

with script_context(snakemake) as log:
    peer = load(snakemake.input.peer)
    table = peers.comparison_frame(peer, load(snakemake.input.mc), load(snakemake.input.x2))  # keys
    write_table(words.p1_words(table), snakemake.output.table,
                caption="A-P1: Basilisk's pixelLineBiasUKF on paper A's measurements beside the EM-EKF, "
                        "the augmented EKF, batch ML and the Cramer-Rao bound (headline case; arcsec; "
                        "mean and sd over seeds, own 3-sigma: median of the estimator's covariance).")
    peers.seed_frame(peer).to_csv(snakemake.output.long, index=False)
    write_json(snakemake.output.summary, words.p1_summary_words(peers.summary(table, peer)))
    log.info("A-P1: %d rows", len(table))
