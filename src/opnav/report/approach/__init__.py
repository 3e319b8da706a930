"""Paper A's presentation: its figures and the words made from its numbers.

The paper package :mod:`opnav.approach` holds the models, estimators and experiments and
returns typed records; this package draws and words them (it imports ``opnav.approach``, never
the reverse: ``tests/test_layers_presentation.py``).

``plots``           A-F4, A-F5, A-F6, A-X1, A-X2, A-X4, A-X7 figures
``star_plots``      A-X6 (the stars study)
``peer_plots``      A-P1 (the peer UKF)
``estimator_plots`` A-X8 (your own estimators)
``text``            the labels' and readings' words, the summary's sentences (why, rule, reason)
"""
