"""One B-X2 ablation job: runs `params.runs` of every ablation method with the
swept config value `params.value` (scatter; seeds from the run index only)."""

from opnav.landing.ablation import with_value
from opnav.landing.montecarlo import run_chunk, save
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(output=["results/landing/ablation/fov/60/depth_r0000-0001.npz"],
                               wildcards={"bsweep": "fov", "bvalue": "60", "bchunk": "r0000-0001"})
    snakemake.params = type("P", (), {"landing": snakemake.config["landing"], "runs": [0, 1],
                                      "methods": ["depth"], "value": 60.0})()

with script_context(snakemake) as log:
    sweep = snakemake.wildcards.bsweep
    cfg = with_value(snakemake.params.landing, sweep, snakemake.params.value)
    runs = list(snakemake.params.runs)
    for method, path in zip(snakemake.params.methods, snakemake.output):
        data = run_chunk(cfg, method, runs)
        save(path, data, method)
        log.info("%s=%s %s: runs %s..%s, %d planning calls", sweep, snakemake.params.value,
                 method, runs[0], runs[-1], len(data["plan_ns"]))
