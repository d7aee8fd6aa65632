"""The shell's materials (fem_reference.shell.ShellParameters), named here so that inputs are
checked without importing dolfinx: "isotropic" (the strip's Poisson ratio, the paper's shell)
and "dep" (the DDG plate's continuum limit)."""
MATERIALS = ("isotropic", "dep")
