/* GRANULAR-CHARGED test driver: MPI-aware GoogleTest main for LAMMPS-driven tests.
   Under mpirun every rank runs every test (LAMMPS commands are collective); only rank 0
   prints GoogleTest's report. */
#include "gtest/gtest.h"

#include <cstdlib>

#include <mpi.h>

bool verbose = false;    // read by LAMMPS's unittest/testing/core.h fixture

int main(int argc, char **argv)
{
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int me = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &me);
  if (me != 0) {
    auto &listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  const char *v = getenv("TEST_VERBOSE");
  if (v && *v && *v != '0') verbose = true;
  int rv = RUN_ALL_TESTS();
  // every rank must agree on failure, otherwise mpirun may report success
  int all = 0;
  MPI_Allreduce(&rv, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return all;
}
