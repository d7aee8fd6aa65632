"""Sweeps of runs over a grid of scenes, executed as tasks on Dask (ddg.sweep.command)."""
