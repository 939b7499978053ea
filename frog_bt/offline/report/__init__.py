"""``frog-bt report``: what a season of recorded tours tells (docs/REPORT.md).

:mod:`~frog_bt.offline.report.facts` reads one file (in a worker),
:mod:`~frog_bt.offline.report.rows` joins the pieces into tours and gives one row each,
:mod:`~frog_bt.offline.report.totals` the figures over the corpus,
:mod:`~frog_bt.offline.report.outputs` writes CSV, Parquet and HTML.
"""
