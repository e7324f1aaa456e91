// Candidate pairs and the count of usable triplets that decides between enumerating every
// triplet and sampling them.

#include <gtest/gtest.h>

#include <random>

#include "pose/pipeline/candidates.hpp"

using namespace ellreloc;

// The count equals a brute-force enumeration of the triplets of pairs with three distinct
// observations, for pair lists in PROSAC order (observations interleaved); observations without
// a candidate (not usable) add nothing.
TEST(Candidates, UsableTripletsCountsTripletsOfDistinctObservations) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 30; ++trial) {
    pipeline::Candidates c;
    const int observations = 1 + trial % 7;
    c.of_observation.resize(static_cast<size_t>(observations));
    for (int o = 0; o < observations; ++o) {
      const int candidates = std::uniform_int_distribution<int>(0, 6)(rng);
      for (int j = 0; j < candidates; ++j) {
        c.of_observation[static_cast<size_t>(o)].push_back(j);
        c.pairs.push_back({o, j, 0.0});
      }
    }
    std::shuffle(c.pairs.begin(), c.pairs.end(), rng);
    const std::vector<pipeline::CandidatePair>& pairs = c.pairs;
    long brute = 0;
    for (size_t i = 0; i < pairs.size(); ++i)
      for (size_t j = i + 1; j < pairs.size(); ++j)
        for (size_t k = j + 1; k < pairs.size(); ++k)
          brute += pairs[i].observation != pairs[j].observation && pairs[i].observation != pairs[k].observation &&
                   pairs[j].observation != pairs[k].observation;
    EXPECT_DOUBLE_EQ(pipeline::usableTriplets(c), static_cast<double>(brute)) << "trial " << trial;
  }
  EXPECT_EQ(pipeline::usableTriplets(pipeline::Candidates{}), 0.0);
}
