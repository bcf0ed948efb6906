#!/bin/sh
# The PETSc methods' set-up (called by `make`): Debian's PETSc (with Open MPI, MUMPS and hypre),
# then mpi4py and petsc4py built against it inside the virtual environment $1.
# PETSc from PyPI builds from source (over 30 min here, without MUMPS), so it is taken from Debian;
# petsc4py must match its version exactly. Without apt or root nothing is installed and the
# petsc methods report themselves as not installed; every other method works.
set -e
VENV=${1:-.venv}
HEADER=/usr/lib/petsc/include/petscversion.h
if [ ! -e "$HEADER" ]; then
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq petsc-dev \
      >/dev/null 2>&1) || { echo "make: petsc-dev not installed; the petsc methods are off"; exit 0; }
  else
    echo "make: no PETSc (Debian: apt-get install petsc-dev as root); the petsc methods are off"
    exit 0
  fi
fi
VERSION=$(awk '/#define PETSC_VERSION_(MAJOR|MINOR|SUBMINOR) /{print $3}' "$HEADER" | paste -sd. -)
if "$VENV/bin/python" -c "import petsc4py, sys; sys.exit(petsc4py.__version__ != '$VERSION')" 2>/dev/null; then
  exit 0
fi
echo "make: building petsc4py $VERSION against /usr/lib/petsc (about 3 minutes)"
"$VENV/bin/python" -m pip install --quiet wheel "mpi4py>=4.0"
PETSC_DIR=/usr/lib/petsc "$VENV/bin/python" -m pip install --quiet --no-build-isolation \
  "petsc4py==$VERSION" || echo "make: petsc4py not built; the petsc methods are off"
