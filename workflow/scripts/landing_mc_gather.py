"""Gather the Monte-Carlo chunks of one method of paper B (in run order)."""

from opnav.landing.montecarlo import gather, load, save
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(input=["results/landing/mc/site-tilt/chunks/depth/r0000-0001.npz"],
                               output=["results/landing/mc/site-tilt/depth.npz"], wildcards={"bmethod": "depth", "bscn": "site-tilt"})

with script_context(snakemake) as log:
    data = gather([load(p) for p in snakemake.input])
    save(snakemake.output[0], {k: v for k, v in data.items() if k != "method"},
         snakemake.wildcards.bmethod)
    log.info("%s: %d runs gathered", snakemake.wildcards.bmethod, len(data["run_index"]))
