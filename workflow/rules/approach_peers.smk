# Paper A, peers on the same data: A-P1, Basilisk's pixelLineBiasUKF (optional extra `peers`).
# Uses approach.smk's and approach_extra.smk's names (APPROACH, A_WORK, A_SRC, A_MC,
# A_METHODS, A_X2, a_groups): include it after both. Without Basilisk the rules are not
# defined and one line says so; everything else still runs.
import importlib.util

A_P1_VARIANTS = config["approach"]["peers"]["variants"]  # inside table1_variants (opnav.core.checks)
# found without importing it (parse time); a None in sys.modules marks it absent, as for import
HAVE_BSK = sys.modules.get("Basilisk", True) is not None and importlib.util.find_spec("Basilisk") is not None


if HAVE_BSK:

    rule approach_peer_ukf:
        """Basilisk's pixelLineBiasUKF on the headline case's measurements of each A-P1 variant
        (same seeds as the EM-EKF), plus the zero-misalignment and truth-start runs; every
        variant in one job (they share the start-up and Basilisk's import, about 2 CPU-s)."""
        input:
            A_SRC + src("approach/peers.py"),
            kernels=kernels("approach"),
        output:
            expand(f"{A_WORK}/peers/{{variant}}.pkl", variant=A_P1_VARIANTS),
        params:
            approach=cfg("approach", "base_seed", "dt_s", "n_seeds", "mars_elements", "geometry",
                         "initial_error", "prior_sigma", "process_noise_diag", "camera",
                         "truth_bias_arcsec", "theta_init_arcsec", "segments", "roll", "peers"),
            variants=A_P1_VARIANTS,
        log:
            f"{APPROACH}/logs/peer_ukf.log",
        benchmark:
            f"{APPROACH}/benchmarks/peer_ukf.tsv"
        script:
            "../scripts/approach_peer_ukf.py"

    rule approach_peer_tables:
        """A-P1 table (the peer beside EM-EKF, augmented EKF, batch ML and the CRLB) and summary."""
        input:
            peer=expand(f"{A_WORK}/peers/{{variant}}.pkl", variant=A_P1_VARIANTS),
            mc=[A_MC[(v, a_groups(v)[0], m)] for v in A_P1_VARIANTS for m in A_METHODS],
            x2=[A_X2[v] for v in A_P1_VARIANTS],
            code=src("approach/peers.py", "report/approach/text.py", "core/tables.py"),
        output:
            table=report_table(f"{APPROACH}/A-P1_peer_ukf", "A-P1", "Paper A"),
            long=f"{A_WORK}/peers/A-P1_seeds.csv",
            summary=f"{APPROACH}/A-P1-summary.json",
        log:
            f"{APPROACH}/logs/peer_tables.log",
        localrule: True
        script:
            "../scripts/approach_peer_tables.py"

    rule approach_peer_figure:
        """A-P1 figure: the peer's (tx, ty) over the arc with its 3 sigma, against the others."""
        input:
            peer=expand(f"{A_WORK}/peers/{{variant}}.pkl", variant=A_P1_VARIANTS),
            table=f"{APPROACH}/A-P1_peer_ukf.csv",
            code=src("report/approach/peer_plots.py", "report/approach/text.py", "core/figures.py", "opnav.mplstyle"),
        output:
            fig=report_figure(f"{APPROACH}/A-P1_peer_ukf", "A-P1", "Paper A"),
        log:
            f"{APPROACH}/logs/peer_figure.log",
        localrule: True
        script:
            "../scripts/approach_peer_figure.py"

else:
    print("opnav: Basilisk (bsk) not installed, skipping A-P1 (peer UKF); "
          "install it with: pip install -e '.[peers]'", file=sys.stderr)
