"""A-X2 table (EM-EKF vs augmented EKF vs batch ML), long form per case, A-X2-summary.json."""

import json
import math
import pickle

import numpy as np

from opnav.approach import alternatives as alt
from opnav.snakeio import script_context
from opnav.tables import atomic_write_text, write_table

if "snakemake" not in globals():  # standalone debugging run
    raise SystemExit("run through snakemake (needs the A-X2 and EM-EKF Monte-Carlo pickles)")


def _clean(x):
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (np.floating, float)):
        x = float(x)
        return x if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


with script_context(snakemake) as log:
    cfg = snakemake.params.approach
    alt_res, em_times = [], {}
    for p in snakemake.input.x2:
        with open(p, "rb") as fh:
            d = pickle.load(fh)
        alt_res.extend(d["results"])
        if d["em_times"]:
            em_times[d["variant"]] = d["em_times"]
    em_res = []
    variants = {r["variant"] for r in alt_res}
    for p in snakemake.input.mc:
        with open(p, "rb") as fh:
            em_res.extend(r for r in pickle.load(fh) if r["variant"] in variants)
    long = alt.long_frame(alt_res, em_res, em_times)
    long.to_csv(snakemake.output.long, index=False)
    table = alt.summary_frame(long)
    write_table(table, snakemake.output.table,
                caption="A-X2: EM-EKF against the augmented EKF and batch ML (IPOPT) on the Table-1 cases; "
                        "errors in arcsec (estimate minus truth), CRLB = Cramer-Rao bound, nav error in km, "
                        "data needed in samples, run time in s per Monte-Carlo seed.")
    summ = alt.summary_json(long, table, cfg)
    summ["profile"] = snakemake.params.profile
    atomic_write_text(snakemake.output.summary, json.dumps(_clean(summ), indent=2, sort_keys=True) + "\n")
    log.info("A-X2: %d long rows, %d table rows", len(long), len(table))
