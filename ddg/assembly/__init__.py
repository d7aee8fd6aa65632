"""The assembly floor that energies and solvers both stand on: scattering element blocks into the
flattened lower band of a symmetric banded matrix (band_scatter) and compiling one kernel apart per
compile-time constant (specialise). It imports nothing else of ddg."""
