"""One Monte-Carlo job of paper B: runs `params.runs` of `wildcards.method` (scatter)."""

from opnav.landing.montecarlo import run_chunk, save
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(output=["results/landing/mc/site-tilt/chunks/depth/r0000-0001.npz"],
                               wildcards={"bmethod": "depth", "bchunk": "r0000-0001"})
    snakemake.params = type("P", (), {"landing": snakemake.config["landing"], "runs": [0, 1]})()

with script_context(snakemake) as log:
    method = snakemake.wildcards.bmethod
    runs = list(snakemake.params.runs)
    data = run_chunk(snakemake.params.landing, method, runs)
    save(snakemake.output[0], data, method)
    log.info("%s: runs %s..%s, %d planning calls", method, runs[0], runs[-1], len(data["plan_index"]))
