"""Post-processing of equilibria: observables (path.csv's columns), centerline curvatures,
the centerline-approximation study, exact solutions, the ribbon's pitchfork diagnostics."""
