"""Validation of the DDG models: the models side by side, against exact solutions, the FEM reference
and the paper; `python -m validation <command>` (validation.cli; `--help` lists the commands).

The rooms, from the floor up:

- table: the one Table class and FigureData, what every room hands to the writers;
- reference, estimates: the paper's values and the FEM gold runs; mesh studies as value objects
  (Richardson extrapolation, error bars);
- claims, verdicts: every agreement the report claims, with its bound; the report's verdicts;
- runs, studies: the report's runs and their cache; the studies each profile needs;
- benchmark: the converged thresholds of the paper's ten scenes (data/benchmark);
- error_map/: each model's error and wall time on every scene with a FEM reference
  (data/error_map): scenes, rows, compute, held_out, readme_writer, plots, command;
- score and scoring/: another code's results scored against the benchmark;
- figures/: every figure drawn from its data alone;
- report_data/, report, templates/: the report's data object, its rendering and the command;
- plate_gold, narrow_limit, wide_check, locking, plate_modes, plate_mesh_scan, paper_figures,
  ribbon_regularisation: the studies behind the committed data;
- command_line, cli: the parser every command shares, the old `python -m validation.<module>`
  spellings as aliases, and the subcommands.
"""
