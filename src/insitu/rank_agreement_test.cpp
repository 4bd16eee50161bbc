// The agreement's wait: how long a waiting rank polls before it sleeps (rank_agreement.hpp). The wait
// itself runs under MPI: insitu.mpi_waits_{1,2,4} (mpi_test.cpp), capi.misuse_*.
#include "insitu/rank_agreement.hpp"

#include <gtest/gtest.h>

using panoptes::insitu::wait_spin_seconds;

TEST(RankAgreement, PollsBrieflyWhereRanksOutnumberCores) {
  EXPECT_DOUBLE_EQ(wait_spin_seconds(2, 2), 100e-6);   // a rank per core: poll through a step's jitter
  EXPECT_DOUBLE_EQ(wait_spin_seconds(1, 64), 100e-6);
  EXPECT_DOUBLE_EQ(wait_spin_seconds(4, 2), 20e-6);    // --oversubscribe: the late rank may need this core
  EXPECT_DOUBLE_EQ(wait_spin_seconds(3, 2), 20e-6);
  EXPECT_DOUBLE_EQ(wait_spin_seconds(0, 2), 100e-6);   // the launcher did not say
  EXPECT_DOUBLE_EQ(wait_spin_seconds(8, 0), 100e-6);   // the core count is unknown
}
