# Sourced by scripts/run and scripts/test: install what is missing (Debian 12,
# as root), then configure and build (incrementally) in build/.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
packages="libdeal.ii-dev numdiff python3-matplotlib openmpi-bin cmake make g++ perl"
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "== installing:$missing"
  if [ "$(id -u)" -ne 0 ]; then
    echo "error: packages missing ($missing) and not root: run 'sudo apt-get install$missing'" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends $missing > /dev/null
fi

# cores, counted before OMP_NUM_THREADS is set (nproc obeys it)
jobs=$(getconf _NPROCESSORS_ONLN)
# Open MPI refuses to run as root unless told that it is wanted.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# one MPI rank per core, no hidden threads inside the BLAS
export OMP_NUM_THREADS=1

mkdir -p "$root/build"
if [ ! -f "$root/build/CMakeCache.txt" ]; then
  echo "== configuring"
  cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release > "$root/build/configure.log"
fi
echo "== building"
cmake --build "$root/build" -j "$jobs" > "$root/build/build.log" 2>&1 || {
  tail -40 "$root/build/build.log" >&2; exit 1; }
