"""Paper B's landmark planner (sec. 2.2, eq. 19-26; SPEC B.3), one module per equation family.

Compiled (``opnav.core.compiled.kernel``), in call order from the bottom:

* :mod:`~opnav.landing.planning.layout`: objective kinds, status codes, the named slots of the
  call's float vectors (q, c, out) and the estimate it plans from;
* :mod:`~opnav.landing.planning.geometry`: the plane holding the velocity, eq. 26, the visible
  interval;
* :mod:`~opnav.landing.planning.depth`: the depth error, eq. 19-25;
* :mod:`~opnav.landing.planning.screens`: the candidate validity rule, the nearest detected
  landmark (bucket grid), the tie rule;
* :mod:`~opnav.landing.planning.hmetrics`: the paper's H baselines in closed form;
* :mod:`~opnav.landing.planning.information`: B-X1's information baselines (the planned
  posterior);
* :mod:`~opnav.landing.planning.search`: the objective, the golden-section search, the call
  (``plan_run``);
* :mod:`~opnav.landing.planning.warmup`: the numba cache warm-up.

:mod:`~opnav.landing.planning.reference` holds the paper's own definitions in numpy, the
reference the tests compare the kernels with and the planner's timed ``paper`` path. Above the
package, ``opnav.landing.metrics`` (the H baselines' context and API) and
``opnav.landing.planner`` (the call as the descent makes it); nothing here imports them.
"""
