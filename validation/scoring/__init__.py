"""The scorecard's machinery behind `python -m validation score` (validation/score.py, whose
docstring is the benchmark's and the results format's contract): the benchmark's scenes (scenes),
a RESULTS file read and checked (results), the scores (scores) and the scorecard written (card)."""
