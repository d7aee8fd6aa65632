"""Studies that run paths: the states at requested shears and the curvature and centerline-error
studies built on them (Figs. 10, A.12-A.14), and the Sadowsky ribbon's pitchfork analysis. They
stand above the api; ddg.analysis below them only measures states."""
