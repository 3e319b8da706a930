"""Parameter studies: sweep config keys of one paper, compare methods on paired runs.

Description
    A study (config section ``studies``, schema ``schemas/studies.schema.yaml``)
    names its paper, one or more dotted config keys with their values
    (``vary``; zipped, or every combination with ``grid: true``), the methods
    (and for paper A the scenario variants) to compare, the runs per value and
    the metrics to tabulate. :func:`opnav.studies.planning.plan` turns every study into
    :class:`~opnav.studies.planning.Study` objects before any job starts:

    * each value set (an *instance*) is merged into a copy of the whole config
      and validated by the project schema (plus any extra check passed in), so
      a bad value is refused naming the study and the key;
    * a swept key must be one the paper's simulation reads (``shape``, the
      simulation's ``params:``), or the sweep would change nothing;
    * the simulation config of an instance (the config projected on
      ``shape``) is content-addressed (:func:`opnav.studies.values.config_digest`):
      identical simulations (the same value in two studies, a value equal to the
      default in another) share their Monte-Carlo jobs, and editing one
      study's values adds only the new value's jobs.

    Runs are paired: run ``i`` uses the paper's stream of run index ``i``
    (paper B: ``SeedSequence([landing.mc.base_seed, i])``; paper A: the
    headline case's ``SeedSequence([approach.base_seed, 1, i])``) at every
    value and for every method, whatever the chunking.

Statistics (:func:`opnav.studies.tables.summarize`), per (instance, [variant,] method,
metric) over the runs: n, mean, sample sd, RMS, median, the 95 % confidence interval of the
mean (Student t, n - 1 degrees of freedom) and the paired difference against the first
method (mean and 95 % interval of the per-run differences).

Modules, by concern (each imported by name; this package re-exports nothing):

* :mod:`.metrics`   what a study can tabulate (per paper), which statistic a figure shows;
* :mod:`.values`    config paths, the simulation's view of a config, its digest, value labels;
* :mod:`.planning`  the ``studies`` section checked and expanded into :class:`Study` objects;
* :mod:`.tables`    the runs gathered, the tidy and wide tables, the statistics, the slopes;
* :mod:`.captions`  a study's caption from its spec.
"""
