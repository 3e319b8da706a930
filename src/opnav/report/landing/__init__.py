"""Paper B's presentation: its figures and the words, rows and tables made from its numbers.

The paper package :mod:`opnav.landing` holds the models, estimators and experiments and
returns typed records; this package draws and words them (it imports ``opnav.landing``, never
the reverse: ``tests/test_layers_presentation.py``).

``plots``         B-F4, B-F5, B-F6, B-F7 and B-X1's envelopes
``timing_plots``  B-F7's overhead curve
``tables``        B-T1, B-T2 (the scenario as tables)
``summary``       B-T3, the summary JSON of a camera scenario, the page views of B-T3 and B-X1,
                  the scorecard rows and verdicts, the end-phase and NEES tables and sentences
``timing_text``   the planning-time method sentence, reductions and the clock in words
"""
