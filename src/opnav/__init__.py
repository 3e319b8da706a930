"""opnav: reproducible Mars optical-navigation studies.

Subpackages
-----------
approach
    Paper A: EM-EKF estimation of the navigation camera's optical-axis bias on
    Mars approach (EKF, RTS smoother, EM, Cramer-Rao bound).
landing
    Paper B: vision-aided inertial navigation for Mars powered descent and
    landmark selection by depth estimation error against observability
    baselines.

Shared modules: :mod:`opnav.core.config` (configuration loading and validation),
:mod:`opnav.core.tables` (CSV/LaTeX/Markdown writers), :mod:`opnav.core.figures` (the
shared matplotlib style and deterministic saving), :mod:`opnav.core.published`
(the papers' published values, always labelled as such).
"""

__version__ = "0.1.0"
