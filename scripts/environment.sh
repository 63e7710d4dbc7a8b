# Sourced by the scripts: Open MPI refuses to run as root (CI, containers)
# unless told, and must be allowed to oversubscribe a 2-core machine.
export OMPI_ALLOW_RUN_AS_ROOT=1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
# The machine's cores, for make and ctest: counted before OMP_NUM_THREADS is
# set below, which GNU nproc would otherwise report.
export IMMERSED_GRAINS_JOBS=${IMMERSED_GRAINS_JOBS:-$(env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc)}
# deal.II and Trilinos threads fight with MPI ranks on small machines.
export DEAL_II_NUM_THREADS=${DEAL_II_NUM_THREADS:-1}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
export CCACHE_DIR=${CCACHE_DIR:-$HOME/.ccache}
# Paths relative to the checkout in ccache's hashes: a second clone (CI's
# fresh one) reuses the objects of the first.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}
# deal.II's Debug flags carry -g (Release ones too with
# IMMERSED_GRAINS_DEBUG_INFO=ON), and with -g ccache hashes the build directory
# (relative to the base directory; for the debug information's working
# directory) unless told not to: build/ and build-dev/ shared no object.
export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
