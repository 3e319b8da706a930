"""Bad input is refused before any job runs, with one line naming the key, flag or file.

The battery (issue 46; :func:`test_battery_counts` prints its counts by class):

* config values: each an overlay on config/config.yaml + config/quick.yaml, checked
  in process with :func:`opnav.preflight.check_config`, which is what the Snakefile
  runs before it builds the DAG (a few `snakemake -n` cases, marked slow, prove that
  path) and what the CLI runs before it computes anything (BAD_CONFIGS: rounds one
  and two; NEW_CONFIGS: round three's classes);
* config files: through `opnav landing --config FILE` in process, whose reader
  (:func:`opnav.core.yamlfile.read_config_file`) the Snakefile calls on every
  --configfile (BAD_FILES, YAML_TRAPS);
* the CLI: `opnav ...` in process (BAD_CLI, NEW_CLI);
* accepted and correct: inputs near the traps that must pass with the right value
  (ACCEPTED_FILES, ACCEPTED_CLI).
"""

import copy

import pytest
import yaml

from conftest import REPO, run_snakemake
from opnav.core.config import ConfigError, _merge
from opnav.preflight import check_config as validate_config


def _raw_quick() -> dict:
    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    _merge(cfg, yaml.safe_load((REPO / "config" / "quick.yaml").read_text()))
    return cfg


_BASE = _raw_quick()

# (overlay YAML, text the error must contain: the key)
BAD_CONFIGS = [
    # non-finite numbers, anywhere
    ("approach: {dt_s: .nan}", "approach.dt_s"),
    ("approach: {dt_s: .inf}", "approach.dt_s"),
    ("approach: {geometry: {range_km: .inf}}", "approach.geometry.range_km"),
    ("approach: {em: {tz_tol: .nan}}", "approach.em.tz_tol"),
    ("approach: {process_noise_diag: [1.0e-4, 1.0e-4, -.inf, 0, 0, 0]}", "approach.process_noise_diag[2]"),
    ("approach: {roll: {rate_deg_s: .nan}}", "approach.roll.rate_deg_s"),
    ("landing: {imu: {sigma_a_mps2: .inf}}", "landing.imu.sigma_a_mps2"),
    ("landing: {gravity_mps2: [0, 0, .nan]}", "landing.gravity_mps2[2]"),
    ("landing: {mc: {runs_per_job: .nan}}", "landing.mc.runs_per_job"),
    ("landing: {planner: {tol_rad: .nan}}", "landing.planner.tol_rad"),
    # integer keys refuse 3.0
    ("approach: {n_seeds: 3.0}", "approach.n_seeds"),
    ("approach: {segments: {N: 50.0}}", "approach.segments.N"),
    ("approach: {alternatives: {batch_ml: {checkpoint_stride: 2.0}}}",
     "approach.alternatives.batch_ml.checkpoint_stride"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, runs: 2.0}}", "studies.s.runs"),
    ("landing: {mc: {n_runs: 3.0}}", "landing.mc.n_runs"),
    ("landing: {mc: {runs_per_job: 3.0}}", "landing.mc.runs_per_job"),
    ("landing: {camera: {pixels: 1024.0}}", "landing.camera.pixels"),
    ("landing: {landmarks: {count: 5.5}}", "landing.landmarks.count"),
    # ranges, types, unknown keys
    ("approach: {segments: {L: 100000}}", "approach.segments.L"),
    ("approach: {mars_elements: {e: 1.0}}", "approach.mars_elements.e"),
    ("approach: {camera: {sigma3_px: [0.1, -0.1, 0.2]}}", "approach.camera.sigma3_px[1]"),
    ("approach: {camera: {sigma3_px: [0, 0.1, 0.2]}}", "approach.camera.sigma3_px[0]"),
    ("approach: {truth_bias_arcsec: [1.0e+9, 0, 0]}", "approach.truth_bias_arcsec[0]"),
    ("approach: {convergence_study: {data_samples: 1000000}}", "approach.convergence_study.data_samples"),
    ("approach: {foo: 1}", "'foo'"),
    ("landing: {camera: {sigma_px: 0}}", "landing.camera.sigma_px"),
    ("landing: {mc: {bounds: {att_deg: 500}}}", "landing.mc.bounds.att_deg"),
    ("profile: fast", "profile"),
    ("paper: {build_pdf: 'yes'}", "paper.build_pdf"),
    # duplicates and lists
    ("approach: {variants: [literal, literal]}", "approach.variants"),
    ("approach: {methods: [plain, plain]}", "approach.methods"),
    ("approach: {variants: [literal, roll], table1_variants: [prior]}", "approach.table1_variants"),
    ("landing: {extra: {methods: [logdet, logdet]}}", "landing.extra.methods"),
    # physics of paper A
    ("approach: {geometry: {range_km: 3000}}", "approach.geometry.range_km"),
    ("approach: {geometry: {v_inf_dir: [0, 0, 0]}}", "approach.geometry.v_inf_dir"),
    ("approach: {geometry: {v_inf_dir: [0, 0, -2]}}", "approach.geometry.v_inf_dir"),
    ("approach: {dt_s: 60, geometry: {range_km: 20000, aim_offset_km: 0}}", "approach.geometry"),
    ("approach: {camera: {ifov_arcsec: 0.1}}", "approach.camera"),
    ("approach: {geometry: {range_km: 20000}}", "approach.camera"),
    ("approach: {truth_bias_arcsec: [6000, 0, 0]}", "approach.truth_bias_arcsec"),
    ("approach: {segments: {N: 100000, L: 10000}}", "approach.segments"),
    ("approach: {n_seeds: 1000, segments: {N0: 10000}}", "approach.n_seeds"),
    ("approach: {roll: {steps_deg: [0, 90], step_interval_s: 100.3}}", "approach.roll.step_interval_s"),
    ("approach: {prior_sigma: {r_km: 1.0e-300}}", "approach.prior_sigma.r_km"),
    ("approach: {initial_error: {r_km: [1.0e+9, 0, 0]}}", "approach.initial_error.r_km[0]"),
    # physics of paper B
    ("landing: {duration_s: 197.5}", "landing.duration_s"),
    ("landing: {filter: {dt_s: 0.7}}", "landing.duration_s"),
    ("landing: {imu: {rate_hz: 2.5}}", "landing.imu.rate_hz"),
    ("landing: {initial_state: {r_m: [3300, 5870, -10]}}", "landing.initial_state.r_m"),
    ("landing: {initial_state: {r_m: [3300, 5870, 2]}}", "landing.initial_state.r_m"),
    ("landing: {initial_state: {v_mps: [0, 0, -200]}}", "landing.initial_state"),
    ("landing: {camera: {tilt_deg: 0}}", "landing.camera"),
    ("landing: {camera: {tilt_azimuth_deg: 73}}", "landing.camera"),
    ("studies: {s: {paper: landing, vary: {camera.fov_deg: [45.0]}}}", "studies.s.vary"),
    ("landing: {figures: {f5_time_s: 500}}", "landing.figures.f5_time_s"),
    ("landing: {figures: {f5_time_s: 1.5}}", "landing.figures.f5_time_s"),
    ("landing: {mc: {n_runs: 100000}}", "landing.mc.n_runs"),
    ("landing: {mc: {bounds: {r_m: 100000}}}", "landing.mc.bounds.r_m"),
    ("landing: {planner: {margin_px: 10000}}", "landing.planner.margin_px"),
    # method names: the planner's registry
    ("landing: {mc: {methods: [depth, nosuch]}}", "landing.mc.methods"),
    ("landing: {extra: {reference: gdopp}}", "landing.extra.reference"),
    ("landing: {single: {method: foo}}", "landing.single.method"),
    ("studies: {s: {paper: moon, vary: {landing.camera.fov_deg: [45.0]}}}", "studies.s.paper"),
    ("landing: {extra: {methods: [], reference: logdet}}", "landing.extra.reference"),
    ("landing: {extra: {n_boot: 1}}", "landing.extra.n_boot"),
    ("approach: {mars_elements: {a_au: 1.0e-9}}", "approach.mars_elements.a_au"),
    ("landing: {gravity_mps2: [0, 0, 0]}", "landing.initial_state"),
    ("landing: {filter: {min_update_altitude_m: 100000}}", "landing.initial_state.r_m"),
    ("approach: {base_seed: true}", "approach.base_seed"),
    # where outputs go
    ("results_dir: ''", "results_dir"),
    ("results_dir: '.'", "results_dir"),
    ("results_dir: paper", "results_dir"),
    ("results_dir: paper/out", "results_dir"),
    ("results_dir: results/../config", "results_dir"),
    # round two (issue 33): where outputs go
    ("results_dir: docs/out", "tracked folder docs/"),
    ("results_dir: .ci", "tracked folder .ci/"),
    ("results_dir: .snakemake/x", "tracked folder .snakemake/"),
    ("results_dir: README.md", "'results_dir': 'README.md' is an existing file"),
    ("results_dir: '" + "a" * 5000 + "'", "'results_dir': 5000 characters"),
    ('results_dir: "res\\0ults"', "'results_dir': contains a NUL byte"),
    ("results_dir: '~nosuchuser33/out'", "'results_dir': '~nosuchuser33/out': '~' names no home"),
    ("results_dir: ..", "'results_dir': '..' holds the checkout"),
    ("results_dir: 7", "'results_dir': 7 is not of type 'string'"),
    # camera scenarios get the landing physics checks of landing.camera
    ("landing: {scenarios: {interior: {fov_deg: 10, tilt_deg: 0}}}", "'landing.scenarios.interior': the landing site"),
    ("landing: {scenarios: {interior: {tilt_azimuth_deg: 73}}}", "'landing.scenarios.interior': the landing site"),
    ("landing: {scenarios: {interior: {pixels: 16}}, planner: {margin_px: 40}}",
     "'landing.scenarios.interior': landing.planner.margin_px = 40 px"),
    ("landing: {scenarios: {wide: {fov_deg: 170, tilt_deg: 0, pixels: 8}}, planner: {margin_px: 4}}",
     "'landing.scenarios.wide.pixels'"),
    ("landing: {scenarios: {interior: {sigma_px: 1.0e-300}}}", "landing.scenarios.interior.sigma_px"),
    ("landing: {scenarios: {interior: {zoom: 2}}}", "landing.scenarios.interior"),
    ("landing: {scenarios: {Wide_1: {}}}", "landing.scenarios"),
    ("landing: {headline_scenario: nadir}", "'landing.headline_scenario': 'nadir' is not one of"),
    ("approach: {growing: {N: 7}}", "'approach.growing.N': 7 does not divide"),
    ("approach: {camera: {sigma3_px: [1.0e-300, 1.0e-300, 2.0e-300]}}", "approach.camera.sigma3_px[0]"),
    # the studies planner: one line per problem, naming studies.<name> and the key
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: 45.0}}}", "'studies.s.vary.landing.camera.fov_deg'"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, colour: red}}", "'studies.s'"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0, 60.0], landing.imu.rate_hz: [10.0]}}}",
     "'studies.s.vary' (study 's'): the vary lists have different lengths"),
    ("studies: {s: {paper: landing, vary: {approach.camera.ifov_arcsec: [10.0]}}}",
     "'studies.s.vary.approach.camera.ifov_arcsec' (study 's')"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, fixed: {landing.camera.fov_deg: 50.0}}}",
     "'studies.s.fixed' (study 's'): key(s) ['landing.camera.fov_deg'] are both swept"),
    ("studies: {s: {paper: landing, vary: {landing.mc.n_runs: [5, 6]}}}",
     "'studies.s.vary.landing.mc.n_runs' (study 's'): key 'landing.mc.n_runs' is not read"),
    ("studies: {s: {paper: landing, vary: {landing.camera.pixels: [512.0]}}}",
     "'studies.s.vary' (study 's'): value landing.camera.pixels = 512.0 refused"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, methods: [depth, oracle]}}",
     "'studies.s.methods' (study 's'): unknown method(s) ['oracle']"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, metrics: [happiness]}}",
     "'studies.s.metrics' (study 's'): unknown metric(s) ['happiness']"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}", "'studies.s.vary' (study 's'): values"),
    ("studies: {s: {paper: landing, vary: {landing.camera.tilt_azimuth_deg: [73.0]}}}",
     "'studies.s.vary' (study 's'): value landing.camera.tilt_azimuth_deg = 73.0 refused: invalid config key "
     "'landing.camera': the landing site"),
    ("studies: {s: {paper: approach, vary: {approach.camera.ifov_arcsec: [10.0, 0.1]}}}",
     "'studies.s.vary' (study 's'): value approach.camera.ifov_arcsec = 0.1 refused: invalid config key 'approach.camera'"),
    ("studies: {s: {paper: landing, variants: [roll], vary: {landing.camera.fov_deg: [45.0]}}}", "'studies.s.variants'"),
    # bounds on the job graph, before it is built
    ("studies: {s: {paper: landing, grid: true, vary: {landing.camera.fov_deg: [" + ", ".join(
        f"{40 + 0.1 * i:.1f}" for i in range(100)) + "], landing.filter.obs_per_landmark: ["
     + ", ".join(str(i) for i in range(1, 101)) + "]}}}",
     "'studies.s.vary' (study 's'): 100 x 100 = 10000 value sets exceed limits.max_study_values"),
    ("landing: {mc: {n_runs: 25000, runs_per_job: 1}}", "'limits.max_jobs': the config makes about"),
    ("limits: {max_jobs: 10}", "'limits.max_jobs'"),
    ("limits: {max_jobs: 0}", "limits.max_jobs"),
]

# Round three (issue 46): (class, overlay, text the error must contain: the key)
NEW_CONFIGS = [
    # names anywhere in the config against the one registry (the schema's $defs.method)
    ("names", "landing: {tuning: {method: oracle}}", "'landing.tuning.method': 'oracle' is not one of"),
    ("names", "landing: {equivalence: {reference: oracle}}", "'landing.equivalence.reference': 'oracle'"),
    ("names", "landing: {equivalence: {controls: [oracle]}}", "'landing.equivalence.controls[0]': 'oracle'"),
    ("names", "landing: {equivalence: {methods: [oracle]}}", "'landing.equivalence.methods[0]': 'oracle'"),
    ("names", "landing: {mc: {methods: [depth, Depth]}}", "'landing.mc.methods[1]': 'Depth'"),
    ("names", "landing: {extra: {methods: [logdet, ' svd']}}", "'landing.extra.methods[1]'"),
    ("names", "landing: {single: {method: 7}}", "'landing.single.method'"),
    ("names", "landing: {equivalence: {controls: [depth]}}", "'landing.equivalence.controls': depth has a metric"),
    ("names", "landing: {equivalence: {methods: [svd]}}", "'landing.equivalence.methods': svd is also the reference"),
    ("names", "approach: {variants: [literal, roll, oracle]}", "'approach.variants[2]': 'oracle'"),
    ("names", "approach: {table1_variants: [stars]}", "'approach.table1_variants[0]': 'stars'"),
    ("names", "approach: {growing: {methods: [squarem, squarem]}}", "'approach.growing.methods': duplicated"),
    ("names", "approach: {peers: {variants: [roll, roll]}}", "'approach.peers.variants': duplicated"),
    ("names", "approach: {em: {method: oracle}}", "'approach.em.method'"),
    ("names", "landing: {extra: {n_runs: {nadir: 5}}}",
     "'landing.extra.n_runs.nadir': 'nadir' is not one of landing.scenarios"),
    # physical minimum and maximum of every number
    ("ranges", "approach: {roll: {rate_deg_s: 1.0e+300}}", "'approach.roll.rate_deg_s': 1e+300 is greater"),
    ("ranges", "approach: {em: {converge_tol_arcsec: 1.0e+300}}", "'approach.em.converge_tol_arcsec'"),
    ("ranges", "approach: {camera: {radius_to_centroid_ratio: 1.0e+300}}",
     "'approach.camera.radius_to_centroid_ratio'"),
    ("ranges", "landing: {initial_state: {att_deg: [1.0e+300, 0, 0]}}", "'landing.initial_state.att_deg[0]'"),
    ("ranges", "approach: {camera: {ifov_arcsec: 1.0e+300}}", "'approach.camera.ifov_arcsec'"),
    ("ranges", "approach: {stars: {every_K: 1000000}}", "'approach.stars.every_K'"),
    ("ranges", "approach: {stars: {mag_limit: -100}}", "'approach.stars.mag_limit': -100 is less than"),
    ("ranges", "approach: {stars: {per_image: 5000}}", "'approach.stars.per_image'"),
    ("ranges", "approach: {stars: {slew_deg: 1000}}", "'approach.stars.slew_deg'"),
    ("ranges", "approach: {process_noise_diag: [1.0e+300, 0, 0, 0, 0, 0]}", "'approach.process_noise_diag[0]'"),
    ("ranges", "approach: {roll: {steps_deg: [1.0e+9]}}", "'approach.roll.steps_deg[0]'"),
    ("ranges", "approach: {growing: {N: 10000000}}", "'approach.growing.N'"),
    ("ranges", "approach: {base_seed: 100000000000000000000000}", "'approach.base_seed'"),
    ("ranges", "approach: {crlb: {theta_prior_sigma_rad: 1.0e+9}}", "'approach.crlb.theta_prior_sigma_rad'"),
    # the claimed accuracy is the analysis plan's (A-C1's target), no longer a config key
    ("unknown", "approach: {accuracy_target_arcsec: 2.0}", "'accuracy_target_arcsec' is no config key any more: "
     "its one home is the analysis plan's claims.A-C1.margins.target_arcsec"),
    # paper A's converged label likewise reads the plan's settings.converge_frac_of_bound
    ("unknown", "approach: {em: {converge_frac_of_bound: 0.1}}", "its one home is the analysis plan's "
     "settings.converge_frac_of_bound"),
    ("unknown", "approach: {em: {bogus_key: 0.1}}", "('bogus_key' was unexpected)"),
    ("unknown", "landing: {mc: {yaw_ratio: 0.5}}", "its one home is the analysis plan's claims.B-C3.margins.yaw_ratio"),
    ("unknown", "landing: {equivalence: {alpha: 0.05}}", "its one home is the analysis plan's level"),
    ("ranges", "approach: {geometry: {v_inf_dir: [1.0e+300, 0, 0]}}", "'approach.geometry.v_inf_dir[0]'"),
    ("ranges", "approach: {roll_rate_study: {rates_deg_s: [0.1, 1.0e+9]}}", "'approach.roll_rate_study.rates_deg_s[1]'"),
    ("ranges", "landing: {gravity_mps2: [0, 0, -1.0e+300]}", "'landing.gravity_mps2[2]'"),
    ("ranges", "landing: {mc: {base_seed: 100000000000000000000000}}", "'landing.mc.base_seed'"),
    ("ranges", "landing: {mc: {converged_pos_err_m: 1.0e+300}}", "'landing.mc.converged_pos_err_m'"),
    ("ranges", "landing: {single: {run_index: 10000000000}}", "'landing.single.run_index'"),
    ("ranges", "landing: {planner: {margin_px: 1.0e+300}}", "'landing.planner.margin_px'"),
    ("ranges", "landing: {scenarios: {interior: {sigma_px: 1.0e+300}}}", "'landing.scenarios.interior.sigma_px'"),
    ("ranges", "landing: {landmarks: {near_site: {r_min_m: 1.0e+300}}}", "'landing.landmarks.near_site.r_min_m'"),
    ("ranges", "landing: {filter: {min_update_altitude_m: 1.0e+300}}", "'landing.filter.min_update_altitude_m'"),
    ("ranges", "landing: {initial_state: {v_mps: [0, 0, -1.0e+300]}}", "'landing.initial_state.v_mps[2]'"),
    ("ranges", "landing: {figures: {f5_time_s: 1.0e+300}}", "'landing.figures.f5_time_s'"),
    ("ranges", "landing: {tuning: {candidates: [[5.0, 3.5]]}}", "'landing.tuning.candidates[0][1]': 3.5 is not of type"),
    ("ranges", "landing: {tuning: {candidates: [[5.0, 3, 1]]}}", "'landing.tuning.candidates[0]'"),
    ("ranges", "landing: {tuning: {candidates: [[500.0, 3]]}}", "'landing.tuning.candidates[0][0]'"),
    ("ranges", "landing: {tuning: {candidates: [[5.0, 30]]}}", "'landing.tuning.candidates[0][1]'"),
    ("ranges", "limits: {max_jobs: 100000000000}", "'limits.max_jobs'"),
    ("ranges", "limits: {max_study_values: 100000000000}", "'limits.max_study_values'"),
    ("ranges", "replication: {approach_n_seeds: 100000}", "'replication.approach_n_seeds'"),
    ("cross-key", "replication: {enabled: true, landing_n_runs: 90000}", "'replication.landing_n_runs': 90000 runs"),
    # cross-key rules
    ("cross-key", "landing: {tuning: {base_seed: 20230410}}", "'landing.tuning.base_seed': 20230410 equals"),
    ("cross-key", "landing: {tuning: {base_seed: 21230413}}\nreplication: {enabled: true, seed_offset: 1000003}",
     "'landing.tuning.base_seed': 21230413 equals landing.mc.base_seed + replication.seed_offset"),
    ("cross-key", "landing: {filter: {update_altitude_margin_m: 10000}}",
     "'landing.filter.update_altitude_margin_m': min_update_altitude_m + update_altitude_margin_m"),
    ("cross-key", "landing: {filter: {min_update_altitude_m: 6000, update_altitude_margin_m: 600}}",
     "'landing.filter.update_altitude_margin_m'"),
    ("cross-key", "landing: {landmarks: {near_site: {r_min_m: 20000}}}",
     "'landing.landmarks.near_site.r_min_m': 20000 m is not inside the landmark field"),
    ("cross-key", "landing: {mc: {converged_pos_err_m: 7000}}", "'landing.mc.converged_pos_err_m': 7000 m is not below"),
    ("cross-key", "landing: {tuning: {n_runs: 100000}}", "'landing.tuning.n_runs': 100000 runs x 198 filter steps"),
    ("cross-key", "approach: {roll_rate_study: {search_deg_s: [20.0, 0.001]}}",
     "'approach.roll_rate_study.search_deg_s': the bracket [20, 0.001]"),
    ("cross-key", "approach: {roll_rate_study: {search_deg_s: [1.0, 1.0]}}", "'approach.roll_rate_study.search_deg_s'"),
    ("cross-key", "approach: {em: {converge_tol_arcsec: 3}}", "'approach.em.converge_tol_arcsec': 3 arcsec exceeds"),
    ("cross-key", "approach: {convergence_study: {tol_arcsec: 5}}", "'approach.convergence_study.tol_arcsec'"),
    ("cross-key", "approach: {em: {converge_tol_arcsec: 2.5}}",
     "'approach.em.converge_tol_arcsec': 2.5 arcsec exceeds the claimed accuracy 2 arcsec (the analysis plan's"),
    ("cross-key", "approach: {camera: {ifov_arcsec: 700}}", "'approach.camera.ifov_arcsec': 700 arcsec x 1024 px"),
    ("cross-key", "approach: {stars: {every_K: 100000}}",
     "'approach.stars.every_K': 100000: the first star image"),
    ("cross-key", "approach: {stars: {sigma_floor_px: 5.0}}", "'approach.stars.sigma_floor_px': 5 px exceeds"),
    ("cross-key", "studies: {big: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, runs: 100000, "
                  "runs_per_job: 100000}}", "'studies.big.runs' (study 'big'): 100000 runs x 198 filter steps"),
    # user-chosen names: file names and rule names
    ("user names", "studies: {runs: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies.runs': the name makes the rule study_runs"),
    ("user names", "studies: {pixel_outputs: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies.pixel_outputs': the name makes the rule study_pixel_outputs"),
    ("user names", "studies: {" + "a" * 250 + ": {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "has 250 characters, at most 40"),
    ("user names", "landing: {scenarios: {" + "b" * 250 + ": {}}}", "'landing.scenarios': 'bbbb"),
    ("user names", "landing: {headline_scenario: " + "c" * 60 + "}", "'landing.headline_scenario'"),
    ("user names", "studies: {'a b': {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies': 'a b' is not a valid name"),
    ("user names", "studies: {'../x': {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies': '../x' is not a valid name"),
    ("user names", "landing: {scenarios: {'Wide/1': {}}}", "'landing.scenarios': 'Wide/1' is not a valid name"),
    ("user names", "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, title: '" + "t" * 300 + "'}}",
     "'studies.s.title'"),
    ("user names", "studies: {s: {paper: landing, grid: true, vary: {landing.camera.fov_deg: [45.0], "
                   "landing.camera.tilt_deg: [45.00000000001], landing.camera.tilt_azimuth_deg: [-107.00000000001], "
                   "landing.camera.sigma_px: [0.500000000001], landing.filter.meas_noise_scale: [5.00000000001], "
                   "landing.filter.depth_sigma_frac: [0.1000000000001], landing.planner.n_sigma_v: [3.0000000000001], "
                   "landing.planner.tol_rad: [0.0010000000001], landing.imu.sigma_a_mps2: [0.00050000000001]}}}",
     "'studies.s.vary' (study 's'): value"),
    # sweeping a map: refused (the stated rule: a value never replaces a whole map)
    ("user names", "studies: {s: {paper: landing, vary: {landing.camera: [{fov_deg: 45.0}]}}}",
     "'studies.s.vary.landing.camera' (study 's'): key 'landing.camera' is a map"),
    ("user names", "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, "
                   "fixed: {landing.camera: {fov_deg: 45.0}}}}", "'studies.s.fixed.landing.camera'"),
    # where outputs go (item 3)
    ("results_dir", "results_dir: '/proc/opnav'", "'results_dir': '/proc/opnav' is under /proc"),
    ("results_dir", "results_dir: '/sys/opnav'", "'results_dir': '/sys/opnav' is under /sys"),
    ("results_dir", "results_dir: '/dev/shm/opnav'", "'results_dir': '/dev/shm/opnav' is under /dev"),
    ("results_dir", "results_dir: \"res\\nults\"", "'results_dir': 'res\\nults' holds a control character"),
    ("results_dir", "results_dir: \"res\\tults\"", "'results_dir': 'res\\tults' holds a control character"),
    ("results_dir", "results_dir: '$HOME/opnav-out'", "'results_dir': '$HOME/opnav-out' holds $HOME"),
    ("results_dir", "results_dir: '${HOME}/opnav-out'", "'results_dir': '${HOME}/opnav-out' holds ${HOME}"),
]


# Round four (issue 57): (class, overlay, text the one error line must contain)
ROUND_FOUR_CONFIGS = [
    ("unchecked", "landing: {tuning: {candidates: [[5.0, 3], [3.0, 3], [5.0, 3]]}}",
     "'landing.tuning.candidates': duplicated [5.0, 3]"),
    ("unchecked", "landing: {tuning: {candidates: [[5.0, 3], [5, 3]]}}", "'landing.tuning.candidates': duplicated"),
    ("unchecked", "profile: full", "'profile': 'full' claims the full profile's samples"),
    ("unchecked", "studies: {s: {paper: landing, id: B-T1, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies.s.id' (study 's'): B-T1 is an output id of the workflow"),
    ("unchecked", "studies: {s: {paper: approach, id: A-F4, vary: {approach.camera.ifov_arcsec: [10.0]}}}",
     "'studies.s.id' (study 's'): A-F4 is an output id"),
    ("unchecked", "studies: {s: {paper: approach, id: B-X9, vary: {approach.camera.ifov_arcsec: [10.0]}}}",
     "'studies.s.id' (study 's'): B-X9 names paper B"),
    ("unchecked", "results_dir: 'my results'", "'results_dir': 'my results' holds ' '"),
    ("unchecked", "results_dir: 'res*'", "'results_dir': 'res*' holds '*'"),
    ("unchecked", "results_dir: 'res?'", "'results_dir': 'res?' holds '?'"),
    ("unchecked", "results_dir: results/quick/report", "'results_dir': 'results/quick/report' is inside the results "
                                                        "folder results/quick/"),
    ("unchecked", "results_dir: results/mine", "'results_dir': 'results/mine' is inside the results folder results/"),
    ("framed", "studies: {runs_pack1: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}\n"
               "jobs: {study_values_per_job: 2}", "'studies.runs_pack1': the name makes the rule study_runs_pack1"),
    ("framed", "studies: {runs_pack7: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}",
     "'studies.runs_pack7': the name makes the rule study_runs_pack7"),
    ("framed", "results_dir: 'results/{x}'", "'results_dir': 'results/{x}' holds '{'"),
    ("framed", "results_dir: 'results/{{x}}'", "'results_dir': 'results/{{x}}' holds '{'"),
    ("framed", "results_dir: 'results/x}'", "'results_dir': 'results/x}' holds '}'"),
    ("noisy", "landing: {mc: {n_runs: 1.0e+300}}", "'landing.mc.n_runs': 1e+300 is not an integer (and far beyond"),
    ("noisy", "approach: {n_seeds: 1.0e+20}", "'approach.n_seeds': 1e+20 is not an integer (and far beyond"),
]

# (overlay, the one line the whole refusal must be: a broken top-level key said once,
# not once per study value)
ONCE = [
    ("profile: fast", "'profile'"),
    ("results_dir: 7", "'results_dir'"),
    ("jobs: 7", "'jobs'"),
    ("jobs: {study_values_per_job: 0}", "'jobs.study_values_per_job'"),
    ("replication: 5", "'replication'"),
    ("replication: {enabled: 3}", "'replication.enabled'"),
    ("paper: {build_pdf: 3}", "'paper.build_pdf'"),
    ("paper: []", "'paper'"),
    ("limits: {max_jobs: -1}", "'limits.max_jobs'"),
]


def _overlaid(overlay: str) -> dict:
    cfg = copy.deepcopy(_BASE)
    _merge(cfg, yaml.safe_load(overlay))
    return cfg


@pytest.mark.parametrize("overlay,key", BAD_CONFIGS, ids=[c[0] for c in BAD_CONFIGS])
def test_bad_config_refused_naming_key(overlay, key):
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO, workflow=True)
    text = str(err.value)
    assert key in text, text
    assert all(line.startswith("invalid config key") or line.startswith("invalid config (top")
               for line in text.splitlines()), text


@pytest.mark.parametrize("cls,overlay,key", NEW_CONFIGS, ids=[f"{c}:{o[:60]}" for c, o, _ in NEW_CONFIGS])
def test_round_three_config_refused_naming_key(cls, overlay, key):
    """Issue 46's classes, in process through the workflow's pre-flight: refused in one
    line per problem naming the key (and what was given)."""
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO, workflow=True)
    text = str(err.value)
    assert key in text, text
    assert all(line.startswith("invalid config key") for line in text.splitlines()), text


@pytest.mark.parametrize("cls,overlay,key", ROUND_FOUR_CONFIGS, ids=[f"{c}:{o[:60]}" for c, o, _ in ROUND_FOUR_CONFIGS])
def test_round_four_config_refused_in_one_line(cls, overlay, key):
    """Issue 57: garbage accepted, accepted unchecked, framed after validation, noisy: each
    refused in one line naming the key, before any job. Mutations (tried): dropping the
    tuning.candidates duplicate check, the output-id check, the workflow's pack patterns
    (workflow_names made=()), or the path characters each fail their cases."""
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO, workflow=True)
    lines = str(err.value).splitlines()
    assert len(lines) == 1 and key in lines[0], lines


@pytest.mark.parametrize("overlay,key", ONCE, ids=[o for o, _ in ONCE])
def test_a_broken_top_level_key_is_said_once(overlay, key):
    """The quick profile plans 8 studies of 2 values: a broken key was repeated once per
    value (17-34 lines blaming studies.<x>.vary). Mutations (tried): planning the studies
    whatever else is broken fails 8 cases; keeping a study value's lines about other
    sections fails results_dir: 7."""
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(overlay), root=REPO, workflow=True)
    lines = str(err.value).splitlines()
    assert len(lines) == 1 and key in lines[0], lines


def test_study_rule_names_are_read_from_the_workflow(tmp_path):
    """The names a study may not take come from the workflow's own rules (rule NAME:, and the
    patterns of rules made in loops), not a hand list: a checkout whose workflow has a rule
    study_extra refuses a study named 'extra'; two studies whose rules collide are refused;
    a name ending in _outputs is fine where no study makes that rule."""
    from opnav.core.checks import workflow_names

    names = workflow_names(REPO)
    assert "study_runs" in names.rules and any(r.fullmatch("approach_mc_pack3") for r in names.made)
    assert not any(r.fullmatch("study_fov") for r in names.made)       # a study's own rules are not reserved
    (tmp_path / "workflow" / "rules").mkdir(parents=True)
    (tmp_path / "workflow" / "report").mkdir()
    (tmp_path / "Snakefile").write_text("rule all:\n    input: []\n")
    (tmp_path / "workflow" / "rules" / "x.smk").write_text(
        "rule study_extra:\n    input: []\nfor i in range(3):\n    rule:\n        name:\n            f\"study_big{i}_x\"\n")
    (tmp_path / "config").mkdir()
    study = "{paper: landing, vary: {landing.camera.fov_deg: [45.0]}}"
    for name, bad in (("extra", "study_extra"), ("big2_x", "study_big2_x"), ("big", None), ("solo_outputs", None)):
        cfg = _overlaid(f"studies: {{{name}: {study}}}\nresults_dir: {tmp_path / 'out'}")
        from opnav.preflight import problems

        lines = problems(cfg, root=tmp_path, workflow=True)
        assert (bad is None) == (not lines) and (bad is None or bad in lines[0]), (name, lines)
    cfg = _overlaid(f"studies: {{a_outputs: {study}, a: {study}}}\nresults_dir: {tmp_path / 'out'}")
    from opnav.preflight import problems

    lines = problems(cfg, root=tmp_path, workflow=True)
    assert len(lines) == 1 and "'studies.a_outputs'" in lines[0] and "study 'a' makes too" in lines[0], lines


def test_full_label_on_full_sizes_passes_and_quick_label_on_any():
    """The label is checked against the sizes it claims, from the schema's defaults (the full
    profile's): full on quick sizes refused (above); full on full sizes, quick on either, pass."""
    from opnav.core.checks import profile_problems      # (the full profile itself: test_quick_and_full_profiles_pass)

    assert not profile_problems(_overlaid("profile: full\napproach: {n_seeds: 20}\nlanding: {mc: {n_runs: 300}}"))
    assert not profile_problems(_overlaid("approach: {n_seeds: 20}\nlanding: {mc: {n_runs: 300}}"))
    assert not profile_problems(_overlaid("{}"))


@pytest.mark.parametrize("where", ["studies", "landing.scenarios", "approach.camera", "", "landing.mc.methods[0]"])
def test_non_string_keys_given_in_process_are_refused(where):
    """A config another reader made (Snakemake's YAML 1.1: `on:` is True) with a key that
    is not a string: refused in one line naming where, before any layer sorts or indexes
    by name (studies.plan's json.dumps raised TypeError). Mutation: dropping the
    non_string_keys layer fails the studies and scenarios cases with a TypeError."""
    cfg = _overlaid("landing: {mc: {methods: [{a: 1}]}}" if where.endswith("[0]") else "{}")
    node = cfg
    for part in filter(None, where.replace("[0]", "").split(".")):
        node = node[part]
    if where.endswith("[0]"):
        node = node[0]
    node[True] = {}
    with pytest.raises(ConfigError) as err:
        validate_config(cfg, root=REPO, workflow=True)
    shown = where.split(".")[0] if where else "(top level)"
    assert "the key True is not a string" in str(err.value) and shown in str(err.value), str(err.value)


def test_quick_and_full_profiles_pass():
    validate_config(_overlaid("{}"), root=REPO, workflow=True)
    # a slow, nearly parabolic approach that does not reach Mars is legal
    validate_config(_overlaid("approach: {geometry: {v_inf_kms: 1.0e-9}}"), root=REPO, workflow=True)
    validate_config(yaml.safe_load((REPO / "config" / "config.yaml").read_text()), root=REPO, workflow=True)


def test_every_problem_gets_its_own_line():
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid("landing: {duration_s: 197.5, imu: {rate_hz: 2.5}}"), root=REPO)
    lines = str(err.value).splitlines()
    assert any("landing.duration_s" in ln for ln in lines)
    assert any("landing.imu.rate_hz" in ln for ln in lines)


def test_the_name_registry_is_the_planners():
    """The schema's registry of method names ($defs.method) is the planner's, the core's
    pickers are the planner's pickers, and the core's copies of the papers' constants are
    theirs (core cannot import the papers). Mutation: a method added to the planner alone
    fails it."""
    from opnav.approach import dynamics, stars
    from opnav.core import checks
    from opnav.landing import planner

    schema = yaml.safe_load((REPO / "src" / "opnav" / "schemas" / "landing.schema.yaml").read_text())
    assert schema["$defs"]["method"]["enum"] == list(planner.available_methods())
    assert set(checks.PICKERS) == set(planner.PICKERS)
    assert checks.R_MARS_KM == dynamics.R_MARS_KM
    a = yaml.safe_load((REPO / "src" / "opnav" / "schemas" / "approach.schema.yaml").read_text())
    mag = a["properties"]["stars"]["properties"]["mag_limit"]
    assert (mag["minimum"], mag["maximum"]) == stars.MAG_RANGE
    a_variants = a["properties"]["variants"]["items"]["enum"]
    from opnav.approach.scenario import VARIANTS
    assert a_variants == list(VARIANTS)


def test_schema_limits_are_numbers():
    """A YAML slip such as `maximum: 1.0e9` (read as a string) would crash validation."""
    def walk(node):
        if isinstance(node, dict):
            for k, v in node.items():
                if k in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
                    assert isinstance(v, (int, float)) and not isinstance(v, bool), (k, v)
                walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)

    for f in (REPO / "src" / "opnav" / "schemas").glob("*.yaml"):
        walk(yaml.safe_load(f.read_text()))


def test_every_number_of_the_schema_has_a_minimum_and_a_maximum():
    """Issue 46 item 1: a number without a physical maximum let 1e300 through (a tolerance
    of 1e300 labelled every run converged). Walks every schema file, $defs followed.
    Mutation: deleting approach.roll.rate_deg_s' maximum fails it."""
    def walk(node, path, defs, out):
        if isinstance(node, dict):
            ref = node.get("$ref", "")
            if ref.startswith("#/$defs/"):
                walk(defs[ref.split("/")[-1]], path, defs, out)
            if node.get("type") in ("number", "integer"):
                lo = "minimum" in node or "exclusiveMinimum" in node
                hi = "maximum" in node or "exclusiveMaximum" in node
                if not (lo and hi):
                    out.append(path)
            for k, v in node.get("properties", {}).items():
                walk(v, f"{path}.{k}", defs, out)
            for key in ("items", "additionalProperties"):
                if isinstance(node.get(key), dict):
                    walk(node[key], f"{path}[]", defs, out)
            for i, v in enumerate(node.get("prefixItems", [])):
                walk(v, f"{path}[{i}]", defs, out)

    open_ = []
    for f in sorted((REPO / "src" / "opnav" / "schemas").glob("*.yaml")):
        schema = yaml.safe_load(f.read_text())
        walk(schema, f.stem, schema.get("$defs", {}), open_)
    assert not open_, open_


@pytest.mark.slow
def test_snakefile_refuses_before_any_job(tmp_path):
    """The workflow's own validation: no job runs, the key is named, nothing is written."""
    from conftest import copy_workflow

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    (wd / "bad.yaml").write_text("approach: {dt_s: .nan}\nlanding: {mc: {runs_per_job: 3.0}}\n")
    proc = run_snakemake(wd, "--cores", "1", "--configfile", "config/quick.yaml", "bad.yaml")
    assert proc.returncode != 0
    out = proc.stdout + proc.stderr
    assert "approach.dt_s" in out and "landing.mc.runs_per_job" in out, out
    assert "Traceback" not in out
    assert not (wd / "results").exists()


def test_all_problems_in_one_pass():
    """Schema and physics problems of different sections, and of studies, in one error."""
    with pytest.raises(ConfigError) as err:
        validate_config(_overlaid(
            "approach: {dt_s: .nan}\nlanding: {headline_scenario: nadir, duration_s: 197.5}\n"
            "results_dir: docs/out\nstudies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}"),
            root=REPO, workflow=True)
    text = str(err.value)
    for key in ("approach.dt_s", "landing.headline_scenario", "landing.duration_s", "results_dir"):
        assert f"'{key}'" in text, text
    with pytest.raises(ConfigError) as err:          # the studies once the papers' sections are sound
        validate_config(_overlaid("results_dir: docs/out\nstudies: {s: {paper: landing, vary: "
                                  "{landing.camera.fov_deg: [45, 45.0]}}, t: {paper: landing, vary: "
                                  "{landing.mc.n_runs: [3]}}}"), root=REPO, workflow=True)
    text = str(err.value)
    assert all(k in text for k in ("'results_dir'", "'studies.s.vary'", "'studies.t.vary.landing.mc.n_runs'")), text


def test_results_dir_tilde_is_expanded():
    import os

    cfg = validate_config(_overlaid("results_dir: ~/opnav-out"), root=REPO)
    assert cfg["results_dir"] == os.path.expanduser("~/opnav-out") and "~" not in cfg["results_dir"]


def test_tracked_folders_come_from_git(tmp_path):
    """A folder that holds tracked files is refused whatever its name; a folder of
    placeholders only (results/README.md) or of untracked files is not."""
    import subprocess

    from opnav.core.checks import results_dir_problems, tracked_dirs

    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    for f in ("notes/a.txt", "results/README.md", "scratch/x.txt"):
        (tmp_path / f).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / f).write_text("x")
    subprocess.run(["git", "-C", str(tmp_path), "add", "notes/a.txt", "results/README.md"], check=True)
    assert {d.as_posix() for d in tracked_dirs(tmp_path)} == {".git", ".snakemake", "notes"}
    assert results_dir_problems("notes/out", tmp_path) and not results_dir_problems("results", tmp_path)
    assert not results_dir_problems("scratch/out", tmp_path)


def test_results_dir_owned_by_one_checkout(tmp_path):
    """The marker names the checkout and profile: another checkout, or the other
    profile, pointed at the same folder is refused in one line; the owner passes (also
    with an edited config); a symlink loop is named. Mutation: owner_problems returning
    [] fails the first assertion."""
    from opnav.core.checks import OWNER_MARKER, claim_results_dir, results_dir_problems

    out = tmp_path / "shared"
    cfg = _overlaid(f"results_dir: {out}")
    claim_results_dir(out, tmp_path / "checkout-a", cfg)
    assert (out / OWNER_MARKER).is_file()
    other = results_dir_problems(cfg, tmp_path / "checkout-b")
    assert len(other) == 1 and "belongs to the checkout" in other[0] and "checkout-a" in other[0], other
    assert results_dir_problems(cfg, tmp_path / "checkout-a") == []
    assert results_dir_problems({**cfg, "landing": {}}, tmp_path / "checkout-a") == []
    quick = results_dir_problems({**cfg, "profile": "other"}, tmp_path / "checkout-a")
    assert len(quick) == 1 and "profile's outputs" in quick[0], quick
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    loop = results_dir_problems(str(tmp_path / "loop" / "x"), tmp_path)
    assert len(loop) == 1 and "symlink loop" in loop[0], loop


def _bomb(levels=9):
    lines = ['a0: &a0 ["x", "x", "x", "x", "x", "x", "x", "x", "x"]']
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]")
    return "\n".join(lines) + "\n"


# (file content (str or bytes, None: absent), text the one-line error must contain)
BAD_FILES = [
    ("landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n",
     "{f}, line 3: key 'landing': given twice (first on line 1)"),
    ("landing:\n  mc: {n_runs: 8, n_runs: 9}\n", "{f}, line 2: key 'landing.mc.n_runs': given twice"),
    ("landing:\n\tmc: {n_runs: 8}\n", "{f}, line 2, column 1: not valid YAML"),
    ("- landing\n- approach\n", "{f}, line 1: the top level must be a mapping of config keys (approach, landing, ...), not a list"),
    ("", "{f}: empty (no config keys)"),
    ("# nothing but a comment\n", "{f}: empty (no config keys)"),
    ("42\n", "{f}, line 1: the top level must be a mapping"),
    ("landing: !!python/object/apply:os.system ['true']\n", "{f}, line 1: key 'landing': the tag"),
    ("landing: !custom {a: 1}\n", "{f}, line 1: key 'landing': the tag '!custom' is refused"),
    (b"\x7fELF\x02\x01\x01\x00\x00\x00\xff\xfe", "{f}, line 1: not UTF-8 text"),
    (b"landing: {}\x00\n", "{f}, line 1: a NUL byte"),
    (None, "{f}: not found"),
    (_bomb(), "{f}, line 1: key 'a0': an anchor (&a0)"),
    ("a: &a [*a]\n", "{f}, line 1: key 'a': an anchor (&a)"),
    ("a: 1\n---\nb: 2\n", "{f}, line 2: more than one YAML document"),
    ("landing: {mc: {n_runs: [1, 2}\n", "{f}, line 1"),
    ("1: {a: 2}\n", "{f}, line 1: key '1': not a name"),
]

# Round three (issue 46 item 2): forms two YAML readers read differently, and what no
# config needs; each refused in one line naming the file, line and key.
YAML_TRAPS = [
    ("approach:\n  base_seed: 020200704\n",
     "{f}, line 2: key 'approach.base_seed': 020200704 has a leading zero: YAML 1.1 reads 4260292 (octal)"),
    ("landing:\n  mc: {n_runs: 010}\n", "{f}, line 2: key 'landing.mc.n_runs': 010 has a leading zero"),
    ("approach: {dt_s: 09}\n", "{f}, line 1: key 'approach.dt_s': 09 has a leading zero"),
    ("approach:\n  dt_s: 1:30\n", "{f}, line 2: key 'approach.dt_s': 1:30 is the base-60 number 90"),
    ("paper:\n  build_pdf: yes\n", "{f}, line 2: key 'paper.build_pdf': 'yes' is the boolean True"),
    ("paper: {build_pdf: off}\n", "{f}, line 1: key 'paper.build_pdf': 'off' is the boolean False"),
    ("paper: {build_pdf: On}\n", "key 'paper.build_pdf': 'On' is the boolean True"),
    ("paper: {build_pdf: NO}\n", "key 'paper.build_pdf': 'NO' is the boolean False"),
    ("on: 1\n", "{f}, line 1: key 'on': not a name: YAML reads this key as the bool True"),
    ("no:\n  a: 1\n", "{f}, line 1: key 'no': not a name"),
    ("landing:\n  mc:\n    yes: 3\n", "{f}, line 3: key 'landing.mc.yes': not a name"),
    ("landing: {null: 1}\n", "{f}, line 1: key 'landing.null': not a name"),
    ("landing: {~: 1}\n", "key 'landing.~': not a name"),
    ("landing: {2.5: 1}\n", "key 'landing.2.5': not a name"),
    ("landing: {planner: {tol_rad: 1e-3}}\n", "key 'landing.planner.tol_rad': 1e-3 is the string '1e-3' in YAML 1.1"),
    ("landing: {planner: {tol_rad: 1.0e-3}, camera: {fov_deg: 6e1}}\n", "key 'landing.camera.fov_deg': 6e1"),
    ("approach: {geometry: {range_km: 1.0e6}}\n", "write 1.0e+6"),
    ("landing: {mc: {n_runs: 1_000}}\n", "key 'landing.mc.n_runs': 1_000 is 1000 in YAML 1.1"),
    ("landing: {mc: {base_seed: 0b101}}\n", "key 'landing.mc.base_seed': 0b101 is 5 in YAML 1.1"),
    ("landing: {mc: {base_seed: 0o17}}\n", "key 'landing.mc.base_seed': 0o17"),
    ("landing: {site: {lon_deg: 2020-07-04}}\n", "key 'landing.site.lon_deg': '2020-07-04' reads as a date"),
    ("landing: {mc: {n_runs: =}}\n", "key 'landing.mc.n_runs': '=' is a YAML 1.1 special key"),
    ("x: &c {fov_deg: 45.0}\nlanding: {camera: {<<: *c, tilt_deg: 40.0}}\n", "{f}, line 1: key 'x': an anchor (&c)"),
    ("landing: {camera: {<<: {fov_deg: 45.0}}}\n", "{f}, line 1: key 'landing.camera': a '<<' merge key"),
    ("landing: {mc: {n_runs: !!int 3}}\n", "key 'landing.mc.n_runs': the tag 'tag:yaml.org,2002:int' is refused"),
    ("landing: {mc: {methods: !!set {depth: null}}}\n", "key 'landing.mc.methods': the tag"),
    ("__use_yte__: true\napproach: {dt_s: 0.5}\n", "{f}, line 1: key '__use_yte__': YTE templates are refused"),
    ("approach: {dt_s: 0.5}\n__use_yte__: true\n", "{f}, line 2: key '__use_yte__'"),
    ("results_dir: $HOME/opnav-out\n", "{f}, line 1: key 'results_dir': '$HOME/opnav-out' holds $HOME"),
    ("results_dir: '${USER}-out'\n", "key 'results_dir': '${{USER}}-out' holds ${{USER}}"),
    ("results_dir: \"a\\x1bb\"\n", "key 'results_dir': value 'a\\x1bb' holds an escape"),
    ("results_dir: \"a\\nb\"\n", "key 'results_dir': value 'a\\nb' holds a newline"),
    ("results_dir: \"a\\u0085b\"\n", "key 'results_dir': value"),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, note: \"x\\u202ey\"}}\n",
     "key 'studies.s.note': value 'x\\u202ey' holds the invisible format character U+202E"),
    ("landing:\n  \"mc\\tx\": 1\n", "{f}, line 2: key 'landing': key 'mc\\tx' holds a tab"),
    ("landing: {\"\": 1}\n", "{f}, line 1: key 'landing': an empty key"),
    ("? [a, b]\n: 1\n", "{f}, line 1: a list or mapping used as a key"),
    ("landing: {? {a: 1} : 2}\n", "{f}, line 1: key 'landing': a list or mapping used as a key"),
    ("a: " + "[" * 40 + "]" * 40 + "\n", "nested more than 32 levels deep"),
    ("landing:\n  mc: {n_runs: 8}\n" + "# padding\n" * 120_000, "bytes, over the 1000000 a config may have"),
    ('{"landing": {"mc": {"n_runs": 8}}, "landing": {}}', "{f}, line 1: key 'landing': given twice"),
    ('{"__use_yte__": true, "approach": {}}', "{f}: key '__use_yte__': YTE templates are refused"),
    ('{"results_dir": "$HOME/x"}', "{f}: key 'results_dir': '$HOME/x' holds $HOME"),
]


@pytest.mark.parametrize("content,expected", BAD_FILES + YAML_TRAPS,
                         ids=[str(c)[:40] for c, _ in BAD_FILES + YAML_TRAPS])
def test_bad_config_file_refused_naming_file_and_line(content, expected, tmp_path, capsys, no_work):
    """Through the CLI (`opnav --config FILE`): one line naming the file (and the line)."""
    from opnav.cli import EXIT_USER, main

    f = tmp_path / "over.yaml"
    if isinstance(content, bytes):
        f.write_bytes(content)
    elif content is not None:
        f.write_text(content)
    assert main(["landing", "--config", str(f)]) == EXIT_USER
    cap = capsys.readouterr()
    lines = cap.err.strip().splitlines()
    assert len(lines) == 1 and expected.format(f=f) in lines[0], cap.err
    assert cap.out == ""


def test_a_directory_is_not_a_config_file(tmp_path):
    from opnav.core.config import read_config_file

    with pytest.raises(ConfigError, match="not a regular file"):
        read_config_file(tmp_path)


@pytest.mark.slow
def test_snakefile_reports_every_problem_in_one_line_each(tmp_path):
    """Problems found by the studies planner, the scenario checks, the growing windows,
    the headline scenario and the job bound all leave through the Snakefile's one wrapper:
    a line each, no Snakemake frames; a duplicated key in a --configfile names file and line."""
    from conftest import copy_workflow

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    (wd / "bad.yaml").write_text(
        "approach: {growing: {N: 7}}\n"
        "landing: {headline_scenario: nadir, scenarios: {interior: {fov_deg: 10, tilt_deg: 0}, site-tilt: {}}}\n"
        "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "bad.yaml")
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0
    assert "'approach.growing.N'" in out and "'landing.headline_scenario'" in out, out
    assert "Traceback" not in out and ".smk\", line" not in out, out
    (wd / "good-scenario.yaml").write_text(
        "landing: {scenarios: {interior: {fov_deg: 10, tilt_deg: 0}, site-tilt: {}}}\n"
        "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "good-scenario.yaml")
    out = proc.stdout + proc.stderr
    problems = [ln for ln in out.splitlines() if ln.startswith("invalid config key")]
    assert [ln.split("'")[1] for ln in problems] == ["landing.scenarios.interior", "studies.s.vary"], out
    (wd / "dup.yaml").write_text("landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n")
    proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", "dup.yaml")
    out = proc.stdout + proc.stderr
    assert proc.returncode != 0 and "dup.yaml, line 3: key 'landing': given twice" in out, out
    assert not (wd / "results").exists()


# ------------------------------------------------------------------ the CLI

def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


# (argv, text stderr must contain: the flag or the file/key); {tmp} is tmp_path
BAD_CLI = [
    (["approach", "--bias", "nan", "0", "0"], "--bias"),
    (["approach", "--bias", "0", "inf", "0"], "--bias"),
    (["approach", "--bias", "1e9", "0", "0"], "--bias"),
    (["approach", "--bias", "6000", "0", "0"], "--bias"),
    (["approach", "--bias", "1", "2"], "--bias"),
    (["approach", "--init", "-inf", "0", "0"], "--init"),
    (["approach", "--init", "0", "50000", "0"], "--init"),
    (["approach", "--pixel-sigma", "nan"], "--pixel-sigma"),
    (["approach", "--pixel-sigma", "0"], "--pixel-sigma"),
    (["approach", "--pixel-sigma", "1e6"], "--pixel-sigma"),
    (["approach", "--N", "3.0"], "--N"),
    (["approach", "--N", "1"], "--N"),
    (["approach", "--N0", "0"], "--N0"),
    (["approach", "--M", "5000"], "--M"),
    (["approach", "--L", "-3"], "--L"),
    (["approach", "--N", "100000", "--L", "10000"], "--N"),
    (["approach", "--seeds", "0"], "--seeds"),
    (["approach", "--seeds", "1001"], "--seeds"),
    (["approach", "--seeds", "2.5"], "--seeds"),
    (["approach", "--seed", "-1"], "--seed"),
    (["approach", "--variant", "nope"], "--variant"),
    (["approach", "--method", "fast"], "--method"),
    (["approach", "--mode", "zigzag"], "--mode"),
    (["landing", "--method", "foo"], "--method"),
    (["landing", "--method", ""], "--method"),
    (["landing", "--seed", "-1"], "--seed"),
    (["landing", "--seed", "1.5"], "--seed"),
    (["landing", "--seed", "abc"], "--seed"),
    (["landing", "--nosuch"], "--nosuch"),
    (["--config", "{tmp}/missing.yaml", "approach"], "missing.yaml"),
    (["--config", "{tmp}/broken.yaml", "landing"], "broken.yaml"),
    (["--config", "{tmp}/nan.yaml", "approach"], "approach.dt_s"),
    (["--config", "{tmp}/tilt.yaml", "landing"], "landing.camera"),
    # round two (issue 33)
    (["approach", "--pixel-sigma", "1e-300"], "--pixel-sigma 1e-300: invalid config key 'approach.camera.sigma3_px[0]'"),
    (["approach", "--set", "approach.variants=[literal]"],
     "--set approach.variants=[literal]: invalid config key 'approach.table1_variants'"),
    (["approach", "--set", "approach.nosuch=1"], "--set approach.nosuch: no config key"),
    (["approach", "--set", "approach.dt_s"], "expected KEY.PATH=VALUE"),
    (["approach", "--set", "approach.dt_s=[1"], "--set approach.dt_s: the value '[1' is not valid YAML"),
    (["landing", "--set", "landing.camera={fov_deg: 45, fov_deg: 50}"], "--set landing.camera: key 'fov_deg': given twice"),
    (["landing", "--set", "landing.headline_scenario=nadir"], "--set landing.headline_scenario"),
    (["landing", "--set", "landing.scenarios.interior.fov_deg=10"], "landing.scenarios.interior"),
    (["landing", "--set", "results_dir=docs/out"], "--set results_dir=docs/out: invalid config key 'results_dir'"),
    (["study", "fov", "--set", "landing.mc.runs_per_job=1", "--set", "landing.mc.n_runs=25000"], "limits.max_jobs"),
    (["study", "fov", "--set", "approach.growing.N=7"], "--set approach.growing.N=7: invalid config key"),
    (["landing", "--config", "{tmp}/dup.yaml"], "dup.yaml, line 3"),
    (["study", "nope", "--config", "{tmp}/nan.yaml"], "approach.dt_s"),
    (["study", "s", "--config", "{tmp}/study.yaml"], "'studies.s.vary' (study 's'): values"),
    (["study", "s", "--config", "{tmp}/study.yaml", "--cores", "0"], "--cores"),
    (["study", "s", "--config", "{tmp}/study.yaml", "--cores", "x"], "--cores"),
    (["study"], "NAME"),
]

# Round three (issue 46 item 5): --set takes any key path and refuses empty and null
# values with the strict reader's rules; a wrong count names the flag; a line caused by
# a flag names the flag and the value the user gave.
NEW_CLI = [
    (["landing", "--set", "landing.mc.n_runs="], "--set landing.mc.n_runs: no value after '='"),
    (["landing", "--set", "landing.mc.n_runs= "], "--set landing.mc.n_runs: no value after '='"),
    (["approach", "--set", "approach=null"], "--set approach: the value 'null' is null"),
    (["landing", "--set", "landing.mc.n_runs=~"], "--set landing.mc.n_runs: the value '~' is null"),
    (["landing", "--set", "landing.duration_s=1"],
     "--set landing.duration_s=1: invalid config key 'landing.figures.f5_time_s'"),
    (["approach", "--bias", "1", "2", "3", "4"], "argument --bias: takes 3 value(s), got 4 (1 2 3 4)"),
    (["landing", "--seed", "1", "2"], "argument --seed: takes 1 value(s), got 2"),
    (["approach", "--init", "1", "2"], "argument --init: expected 3 arguments"),
    (["approach", "--pixel-sigma", "60"], "--pixel-sigma 60.0: invalid config key 'approach.camera.sigma3_px[2]'"),
    (["landing", "--set", "landing.mc.base_seed=010"], "--set landing.mc.base_seed: 010 has a leading zero"),
    (["landing", "--set", "paper.build_pdf=yes"], "--set paper.build_pdf: 'yes' is the boolean True"),
    (["landing", "--set", "landing.planner.tol_rad=1e-3"], "--set landing.planner.tol_rad: 1e-3 is the string"),
    (["landing", "--set", "approach.dt_s=1:30"], "--set approach.dt_s: 1:30 is the base-60 number 90"),
    (["landing", "--set", "results_dir=$HOME/x"], "--set results_dir: '$HOME/x' holds $HOME"),
    (["landing", "--set", "results_dir=/proc/opnav"], "--set results_dir=/proc/opnav: invalid config key 'results_dir'"),
    (["landing", "--set", "landing.scenarios.site-tilt.zoom=2"],
     "--set landing.scenarios.site-tilt.zoom: no config key 'landing.scenarios.site-tilt.zoom'"),
    (["landing", "--set", "landing.scenarios.nosuch.fov_deg=75"],
     "--set landing.scenarios.nosuch.fov_deg: no config key"),
    (["landing", "--set", "landing.tuning.method=oracle"],
     "--set landing.tuning.method=oracle: invalid config key 'landing.tuning.method': 'oracle' is not one of"),
    (["landing", "--set", "landing.equivalence.controls=[oracle]"], "--set landing.equivalence.controls=[oracle]"),
    (["landing", "--set", "landing..mc=1"], "expected KEY.PATH=VALUE"),
    (["landing", "--set", "=1"], "expected KEY.PATH=VALUE"),
    (["landing", "--set", "landing.camera=7"], "--set landing.camera=7: invalid config key 'landing.camera'"),
    (["landing", "--set", "landing.mc.n_runs=3.0"], "--set landing.mc.n_runs=3.0: invalid config key 'landing.mc.n_runs'"),
    (["landing", "--set", "landing.filter.update_altitude_margin_m=10000"],
     "--set landing.filter.update_altitude_margin_m=10000: invalid config key 'landing.filter.update_altitude_margin_m'"),
    (["landing", "--set", "landing.tuning.base_seed=20230410"], "--set landing.tuning.base_seed=20230410"),
    (["landing", "--set", "landing.mc={n_runs: 4,n_runs: 5}"], "--set landing.mc: key 'n_runs': given twice"),
    (["landing", "--set", "landing.camera.fov_deg=\"45\\n\""], "--set landing.camera.fov_deg: value '45\\n' holds a newline"),
    (["study", "fov", "--set", "approach.stars.mag_limit=-100"],
     "--set approach.stars.mag_limit=-100: invalid config key 'approach.stars.mag_limit'"),
    (["study", "fov", "--set", "landing.tuning.method=oracle"], "--set landing.tuning.method=oracle"),
    (["landing", "--config", "{tmp}/trap.yaml"], "trap.yaml, line 1: key 'landing.mc.base_seed': 010 has a leading zero"),
    (["approach", "--variant", "stars", "--set", "approach.stars.every_K=100000"],
     "invalid config key 'approach.stars.every_K': 100000: the first star image"),
    (["study", "fov", "--config", "{tmp}/yte.yaml"], "yte.yaml, line 1: key '__use_yte__'"),
]


# Round four (issue 57): (argv, text stderr must contain)
ROUND_FOUR_CLI = [
    (["approach", "--config", "config/quick.yaml", "--bogus-flag"], "unrecognized flag --bogus-flag"),
    (["approach", "--set", "approach.n_seeds=-"], "--set approach.n_seeds: the value '-' reads as [null]"),
    (["approach", "--set", "approach={}"], "--set approach={}: an empty map would replace the whole map"),
    (["approach", "--config", "config/quick.yaml", "--set", "approach={}"], "--set approach={}"),
    (["landing", "--set", "landing.camera={fov_deg: 45}"], "--set landing.camera={fov_deg: 45}: a map without"),
    (["approach", "--seed", "1000000000", "--seeds", "2"], "--seed 1000000000"),
    (["approach", "--seed", "99999999999999999999"], "--seed 99999999999999999999"),
    (["landing", "--seed", "99999999999999999999"], "--seed"),
    (["check"], "CONFIG"),
    (["check", "{tmp}/nosuch.yaml"], "nosuch.yaml: not found"),
    (["check", "{tmp}/study.yaml", "--timeout", "0"], "--timeout"),
]


@pytest.fixture()
def no_work(monkeypatch):
    """Any simulation started fails the test: refusal must come first."""
    import opnav.approach.cases as cases
    import opnav.approach.scenario as scenario
    import opnav.landing.descent as descent

    def forbidden(*a, **k):
        raise AssertionError("work started before the input was refused")

    for mod, name in ((cases, "run_case"), (scenario, "build_geometry"),
                      (descent, "build_scenario"), (descent, "run_descent")):
        monkeypatch.setattr(mod, name, forbidden)


@pytest.mark.parametrize("argv,named", BAD_CLI + NEW_CLI + ROUND_FOUR_CLI,
                         ids=[" ".join(a) for a, _ in BAD_CLI + NEW_CLI + ROUND_FOUR_CLI])
def test_bad_cli_refused_naming_flag(argv, named, tmp_path, capsys, no_work):
    from opnav.cli import EXIT_USER, main

    _write(tmp_path, "broken.yaml", "approach: {dt_s: [1, 2\n")
    _write(tmp_path, "nan.yaml", "approach: {dt_s: .nan}\n")
    _write(tmp_path, "tilt.yaml", "landing: {camera: {tilt_deg: 0}}\n")
    _write(tmp_path, "dup.yaml", "landing:\n  mc: {n_runs: 8}\nlanding:\n  duration_s: 198\n")
    _write(tmp_path, "study.yaml", "studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45, 45.0]}}}\n")
    _write(tmp_path, "trap.yaml", "landing: {mc: {base_seed: 010}}\n")
    _write(tmp_path, "yte.yaml", "__use_yte__: true\n")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    try:
        rc = main(argv)
    except SystemExit as exc:          # argparse's own refusals
        rc = exc.code
    cap = capsys.readouterr()
    assert rc == EXIT_USER, (rc, cap.err)
    assert named in cap.err, cap.err
    assert cap.out == ""
    assert "Traceback" not in cap.err
    assert all(line.startswith("opnav") for line in cap.err.strip().splitlines()), cap.err


def test_numerical_failure_is_one_line(monkeypatch, capsys):
    import numpy as np

    import opnav.landing.descent as descent
    from opnav.cli import EXIT_NUMERICAL, main

    def singular(*a, **k):
        raise np.linalg.LinAlgError("Matrix is not positive definite")

    monkeypatch.setattr(descent, "run_descent", singular)
    assert main(["landing"]) == EXIT_NUMERICAL
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not positive definite" in err[0]


def test_json_output_is_strict():
    """NaN and infinities (also numpy's) are written as null: valid JSON."""
    import json

    import numpy as np

    from opnav.core.tables import json_ready

    obj = {"a": float("nan"), "b": [float("inf"), 1.5], "c": np.float64("nan"), "d": np.array([1.0, np.nan]),
           "e": "nan", "f": 3}
    text = json.dumps(json_ready(obj), allow_nan=False)

    def refuse(c):
        raise ValueError(c)

    back = json.loads(text, parse_constant=refuse)
    assert back == {"a": None, "b": [None, 1.5], "c": None, "d": [1.0, None], "e": "nan", "f": 3}


# ------------------------------------------------------------------ accepted and correct

# (file content, dotted key, the value it must have): near the traps, read alike by
# Snakemake's reader and ours, accepted with that value.
ACCEPTED_FILES = [
    ("landing: {planner: {tol_rad: 1.0e-3}}\n", "landing.planner.tol_rad", 0.001),
    ("landing: {planner: {tol_rad: 1.0e-3}}\r\n", "landing.planner.tol_rad", 0.001),
    ('{"landing": {"planner": {"tol_rad": 1e-3}}}', "landing.planner.tol_rad", 0.001),
    ("paper: {build_pdf: false}\n", "paper.build_pdf", False),
    ("paper: {build_pdf: True}\n", "paper.build_pdf", True),
    ("landing: {mc: {n_runs: 0x10}}\n", "landing.mc.n_runs", 16),
    ("landing: {camera: {fov_deg: +45}}\n", "landing.camera.fov_deg", 45),
    ("landing: {mc: {n_runs: 0}}\n", "landing.mc.n_runs", 0),
    (b"\xef\xbb\xbflanding: {mc: {n_runs: 8}}\n", "landing.mc.n_runs", 8),
    ("studies: {s: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}, note: 'yes, 1:30 and 010'}}\n",
     "studies.s.note", "yes, 1:30 and 010"),
    ("landing: {scenarios: {'on': {}}}\n", "landing.scenarios.on", {}),
    ("results_dir: 'out/a$'\n", "results_dir", "out/a$"),
    ("approach: {base_seed: !!str 5}\n", "approach.base_seed", "5"),
]


@pytest.mark.parametrize("content,key,value", ACCEPTED_FILES, ids=[str(c)[:40] for c, _, _ in ACCEPTED_FILES])
def test_accepted_file_reads_as_snakemake_reads_it(content, key, value, tmp_path):
    """Accepted with the value both readers give: ours and Snakemake's (JSON first, then
    PyYAML, snakemake.common.configfile)."""
    from snakemake.common.configfile import load_configfile

    from opnav.core.yamlfile import read_config_file

    f = tmp_path / "ok.yaml"
    f.write_bytes(content if isinstance(content, bytes) else content.encode())
    ours = read_config_file(f)
    node = ours
    for part in key.split("."):
        node = node[part]
    assert node == value and type(node) is type(value), (node, value)
    assert ours == load_configfile(str(f))


def _cli_config(argv):
    from opnav.cli import build_parser, load_cli_config

    return load_cli_config(build_parser().parse_args(argv))


def test_set_takes_any_key_path():
    """--set a key of a camera scenario (its name holds '-'), a key the scenario's overlay
    does not hold yet, and a whole list; the values are the user's."""
    cfg = _cli_config(["landing", "--set", "landing.scenarios.site-tilt.fov_deg=75",
                       "--set", "landing.mc.methods=[depth, svd]", "--set", "landing.planner.tol_rad=1.0e-3"])
    assert cfg["landing"]["scenarios"]["site-tilt"]["fov_deg"] == 75
    assert cfg["landing"]["mc"]["methods"] == ["depth", "svd"]
    assert cfg["landing"]["planner"]["tol_rad"] == 0.001


def test_user_errors_exit_2_and_numerical_failures_3(monkeypatch, capsys):
    """A ValueError naming a config key from inside the package is the user's (2); any
    other failure of a computation is numerical (3)."""
    import opnav.landing.descent as descent
    from opnav.cli import EXIT_NUMERICAL, EXIT_USER, main

    def user(*a, **k):
        raise ValueError("landing.timing.max_calls_paper must be >= 0, got -1")

    monkeypatch.setattr(descent, "run_descent", user)
    assert main(["landing"]) == EXIT_USER
    assert "opnav: error: landing.timing.max_calls_paper" in capsys.readouterr().err

    def numerical(*a, **k):
        raise ValueError("Eigenvalues did not converge")

    monkeypatch.setattr(descent, "run_descent", numerical)
    assert main(["landing"]) == EXIT_NUMERICAL


def test_battery_counts():
    """The battery's size by class (issue 46's done-when: at least 150 cases)."""
    import collections

    counts = collections.Counter({"config values, rounds 1-2": len(BAD_CONFIGS),
                                  "config files, rounds 1-2": len(BAD_FILES),
                                  "YAML traps (files)": len(YAML_TRAPS),
                                  "CLI, rounds 1-2": len(BAD_CLI), "CLI, round 3": len(NEW_CLI),
                                  "CLI, round 4": len(ROUND_FOUR_CLI),
                                  "accepted files": len(ACCEPTED_FILES),
                                  "round four (config values)": len(ROUND_FOUR_CONFIGS) + len(ONCE)})
    counts.update(cls for cls, _, _ in NEW_CONFIGS)
    print("\n" + "\n".join(f"{n:4d}  {k}" for k, n in counts.items()) + f"\n{sum(counts.values()):4d}  total")
    assert sum(counts.values()) >= 150


# (overlay file content, text the Snakefile's refusal must hold)
SNAKEMAKE_CASES = [
    ("approach:\n  base_seed: 020200704\n", "line 2: key 'approach.base_seed': 020200704 has a leading zero"),
    ("__use_yte__: true\napproach: {dt_s: 0.5}\n", "line 1: key '__use_yte__': YTE templates are refused"),
    ("landing: {tuning: {method: oracle}}\n", "invalid config key 'landing.tuning.method': 'oracle'"),
    ("studies: {runs: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}\n",
     "invalid config key 'studies.runs': the name makes the rule study_runs"),
    ("results_dir: /proc/opnav\n", "invalid config key 'results_dir': '/proc/opnav' is under /proc"),
    # round four: these ended in CreateRuleException and WildcardError after validation
    ("jobs: {study_values_per_job: 2}\nstudies: {runs_pack1: {paper: landing, vary: {landing.camera.fov_deg: [45.0]}}}\n",
     "invalid config key 'studies.runs_pack1': the name makes the rule study_runs_pack1"),
    ("results_dir: 'results/{x}'\n", "invalid config key 'results_dir': 'results/{x}' holds '{'"),
    ("profile: full\n", "invalid config key 'profile': 'full' claims"),
]


@pytest.mark.slow
def test_snakemake_dry_run_refuses_round_three_input(tmp_path):
    """End to end through `snakemake -n`: the same refusals as in process, one line after
    'ConfigError (no job was run):', no traceback, no rule error, nothing written."""
    from conftest import copy_workflow, run_snakemake

    (tmp_path / "wf").mkdir()
    wd = copy_workflow(tmp_path / "wf")
    for i, (content, expected) in enumerate(SNAKEMAKE_CASES):
        (wd / f"bad{i}.yaml").write_text(content)
        proc = run_snakemake(wd, "-n", "--cores", "1", "--configfile", "config/quick.yaml", f"bad{i}.yaml")
        out = proc.stdout + proc.stderr
        assert proc.returncode != 0 and "ConfigError (no job was run):" in out, out[-2000:]
        assert expected in out and "Traceback" not in out and "CreateRuleException" not in out, out[-2000:]
        assert "WildcardError" not in out, out[-2000:]
    assert not (wd / "results").exists()


@pytest.mark.parametrize("profile,marker,expect", [
    ("full", "quick", ["'profile'"]),          # the label is wrong: only the label is said
    ("quick", "full", ["'results_dir'"]),      # control: a right label, another profile's folder
])
def test_a_wrong_profile_label_is_not_said_again_as_the_folder_owner(tmp_path, profile, marker, expect):
    """A results_dir owned by another profile follows from a wrong ``profile`` label: one line
    (the label), whatever the checkout's own results/ holds (the test makes its own folder).
    Mutation (tried): the owner check run whatever the label fails the first case."""
    import json

    from opnav.core.checks import OWNER_MARKER, config_problems

    out = tmp_path / "out"
    out.mkdir()
    (out / OWNER_MARKER).write_text(json.dumps({"checkout": str(REPO.resolve()), "profile": marker}))
    cfg = _overlaid(f"profile: {profile}\nresults_dir: {out}")
    lines = config_problems(cfg, root=REPO, workflow=True)
    assert len(lines) == len(expect) and all(k in line for k, line in zip(expect, lines)), lines
