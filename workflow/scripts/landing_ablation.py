"""B-X2: one ablation sweep of paper B (field of view or observations per
landmark): table and figure of accuracy, NEES, landmarks and planning time vs
the swept value, per method."""

from collections import defaultdict
from pathlib import Path


from opnav import figures
from opnav.landing.ablation import SWEEPS, parse_value, sweep_table
from opnav.landing.montecarlo import gather, load
from opnav.snakeio import mock_snakemake, script_context
from opnav.tables import write_table

if "snakemake" not in globals():  # standalone debugging run
    snakemake = mock_snakemake(
        input={"runs": sorted(str(p) for p in Path("results/landing/ablation/fov").glob("*/*.npz"))},
        output={"t": ["results/landing/B-X2_ablation_fov.csv"],
                "f": ["results/landing/B-X2_ablation_fov.pdf"]})
    snakemake.params = type("P", (), {"sweep": "fov", "values": [45.0, 60.0], "methods": ["depth", "svd"],
                                      "default": 60.0, "converged_pos_err_m": 100.0})()

PANELS = (("final_pos_err_m", "final position error (m)"),
          ("rms_pos_err_m", "RMS position error (m)"),
          ("final_vel_err_mps", "final velocity error (m/s)"),
          ("rms_vel_err_mps", "RMS velocity error (m/s)"),
          ("mean_nees_pos", "mean position NEES (-)"),
          ("landmarks_per_run", "landmarks used per run (-)"),
          ("median_plan_time_us", "median planning time (us)"),
          ("median_plan_cpu_us", "median planning CPU time (us)"),
          ("no_pick_pct", "plans choosing no landmark (%)"))


def figure(df, col, xlabel, methods, default):
    import matplotlib.pyplot as plt

    from opnav.landing.plots import METHOD_COLORS, METHOD_LABELS

    with figures.style():
        fig, axs = plt.subplots(3, 3, figsize=(figures.PAGE_WIDTH_IN, 5.4), sharex=True,
                                constrained_layout=True)
        for ax, (key, ylabel) in zip(axs.ravel(), PANELS):
            for k, m in enumerate(methods):
                d = df[df["method"] == m].sort_values(col)
                c = METHOD_COLORS.get(m, f"C{k}")
                lab = METHOD_LABELS.get(m, m)
                # earlier methods drawn wider underneath, so identical curves stay visible
                w = 1.0 + 1.2 * (len(methods) - 1 - k)
                if f"{key}_mean" in d:
                    ax.plot(d[col], d[f"{key}_mean"], "o-", color=c, ms=2 + w, lw=w, label=f"{lab} mean")
                    ax.plot(d[col], d[f"{key}_3sigma"], "s--", color=c, ms=1.5 + w, lw=0.8 * w,
                            label=f"{lab} 3-sigma")
                else:
                    ax.plot(d[col], d[key], "o-", color=c, ms=2 + w, lw=w, label=lab)
            if key.startswith(("final_", "rms_", "median_", "mean_nees")):
                ax.set_yscale("log")
            ax.axvline(default, color="0.6", lw=0.6, ls=":")
            ax.set_ylabel(ylabel, fontsize="small")
        for ax in axs[-1]:
            ax.set_xlabel(xlabel)
        axs[0, 0].legend(loc="best", fontsize="x-small")
        return fig


with script_context(snakemake) as log:
    sweep = snakemake.params.sweep
    col, _, _, unit, _ = SWEEPS[sweep]
    parts = defaultdict(list)
    for p in snakemake.input.runs:
        p = Path(p)
        value = parse_value(sweep, p.parent.name, snakemake.params.values)
        method = p.name.rsplit("_", 1)[0]
        parts[(value, method)].append(load(p))
    data = defaultdict(dict)
    for value in snakemake.params.values:
        for m in snakemake.params.methods:
            data[value][m] = gather(parts[(value, m)])
    df = sweep_table(sweep, dict(data), float(snakemake.params.converged_pos_err_m))
    what = {"fov": "camera full field of view (deg)",
            "obs": "observations per unknown landmark before a new one is planned"}[sweep]
    write_table(df, snakemake.output.t,
                caption=(f"B-X2: ablation of the {what}, every other setting as configured "
                         f"(configured value {snakemake.params.default:g}); per value and method, "
                         "final and RMS position (m) and velocity (m/s) error norms over the paired "
                         "runs (mean and 3-sigma), mean NEES, landmarks used per run and median "
                         "planning-call time (us)."))
    xlabel = {"fov": "camera field of view (deg)", "obs": "observations per landmark (-)"}[sweep]
    figures.save(figure(df, col, xlabel, list(snakemake.params.methods), snakemake.params.default),
                 snakemake.output.f)
    log.info("B-X2 %s:\n%s", sweep, df.to_string())
