#!/bin/sh
# The distributed tests on several MPI processes: run_distributed_tests.sh MPIEXEC PROCESSES
# TEST_PROGRAM (CMakeLists.txt, mess_distributed_*_ranks).
#
# Open MPI 4.1 (Debian 12) sometimes ends a job whose processes all called MPI_Finalize with
# "mpiexec has exited due to process rank R with PID 0 on node ... exiting improperly" when the
# machine is busy (open-mpi/ompi#9389; seen once in a CI run here, after every process had
# passed every test). Only in that case, with every process's "[  PASSED  ]" line printed and
# that message the only failure, the job is run once more, and the second run must pass as it
# is. Any failing test fails at once.
set -u
mpiexec=$1
processes=$2
program=$3
log=$(mktemp)
trap 'rm -f "$log"' EXIT

run() {
  "$mpiexec" --allow-run-as-root --oversubscribe -np "$processes" "$program" \
    --gtest_filter='Distributed*' > "$log" 2>&1
  status=$?
  cat "$log"
  return "$status"
}

run && exit 0
status=$?
passed=$(grep -c 'PASSED  \]' "$log")
if [ "$passed" -eq "$processes" ] && ! grep -q 'FAILED  \]' "$log" &&
  grep -q 'PID 0 on' "$log"; then
  echo "run_distributed_tests.sh: every process passed, but Open MPI reported an improper exit" \
    "(PID 0); running the job once more"
  run
  exit $?
fi
exit "$status"
