#!/usr/bin/env bash
# Install everything the project needs on Debian 12 (as root) into ./.venv.
# libopenblas0-pthread replaces Debian's reference BLAS/LAPACK (update-alternatives): the plate's
# banded Cholesky at 2000 triangles takes 3.4 ms with it (one thread) against 21.6 ms without.
# Debian's python3-dolfinx is built for /usr/bin/python3 and its numpy, so the virtualenv sees
# the system site-packages and pip is never allowed to replace numpy or scipy (constraints).
set -euo pipefail
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive
APT_PACKAGES="python3 python3-venv python3-pip python3-numpy python3-scipy python3-numba python3-dolfinx python3-slepc4py python3-gmsh gmsh python3-meshio python3-matplotlib python3-jinja2 python3-dask python3-distributed python3-pandas chromium libegl1 libegl-mesa0 libopenblas0-pthread python3-sphinx python3-numpydoc python3-sphinx-gallery python3-myst-parser furo"
missing=""
for p in $APT_PACKAGES; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  apt-get update -q
  apt-get install -y -q --no-install-recommends $missing
fi
if [ ! -x .venv/bin/python ]; then
  /usr/bin/python3 -m venv --system-site-packages .venv
fi
# pin numpy and scipy to the Debian builds that dolfinx was compiled against
/usr/bin/python3 -c "import numpy, scipy; print(f'numpy=={numpy.__version__}'); print(f'scipy=={scipy.__version__}')" > .venv/constraints.txt
.venv/bin/python -m pip install -q --disable-pip-version-check -c .venv/constraints.txt -r requirements-dev.txt
.venv/bin/python -m pip install -q --disable-pip-version-check -c .venv/constraints.txt --no-build-isolation --no-deps -e .
.venv/bin/python -c "import numpy, scipy, numba, ddg; print('ddg', ddg.__version__, 'numpy', numpy.__version__, 'scipy', scipy.__version__, 'numba', numba.__version__)"
# compile the numba kernels once and cache them (ddg/**/__pycache__), so no run pays the JIT cost
.venv/bin/python -m ddg warmup
