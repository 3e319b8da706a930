"""B-F6 (navigation-error 3-sigma envelopes) and B-F7 (planning-time box plots)."""

from opnav import figures, published
from opnav.landing import plots, timing
from opnav.landing.montecarlo import load
from opnav.snakeio import mock_snakemake, script_context

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(
        input={"mc": [f"results/landing/mc/site-tilt/{m}.npz" for m in ("depth", "svd", "gdop", "cond")],
               "timing": "results/landing/timing/site-tilt.npz"},
        output={"f6": ["results/landing/B-F6_nav_error_envelopes_site-tilt.pdf",
                       "results/landing/B-F6_nav_error_envelopes_site-tilt.png"],
                "f7": ["results/landing/B-F7_planning_time_site-tilt.pdf",
                       "results/landing/B-F7_planning_time_site-tilt.png"]})
    snakemake.params = type("P", (), {"methods": ["depth", "svd", "gdop", "cond"]})()

with script_context(snakemake) as log:
    data = {m: load(p) for m, p in zip(snakemake.params.methods, snakemake.input.mc)}
    t = next(iter(data.values()))["t"]
    figures.save(plots.fig_nav_error_envelopes(t, data), snakemake.output.f6)
    pub = published.paper_b()["depth_time_reduction_vs_svd_pct"]
    tm = timing.load(snakemake.input.timing)     # planning times by replay, not the descents'
    figures.save(plots.fig_planning_time(tm, list(data), pub), snakemake.output.f7)
    log.info("B-F6, B-F7 from %s", list(data))
