// gravcal/simulation/simulated_attitudes.h: the attitudes file a fixture
// would give for a simulated session (for the known-attitude method).
#ifndef GRAVCAL_SIMULATION_SIMULATED_ATTITUDES_H_
#define GRAVCAL_SIMULATION_SIMULATED_ATTITUDES_H_

#include <cstdint>
#include <vector>

#include "gravcal/io/attitude_fixture.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {

// The fixture file of a simulated session: each pose's time window and its
// true roll, pitch and heading plus N(0, noise_deg) (a stream of its own from
// seed), with std max(noise_deg, 0.001).
std::vector<FixtureAttitude> SimulatedFixtureAttitudes(const SimulatedSession& session,
                                                       double noise_deg, uint64_t seed);

}  // namespace gravcal

#endif  // GRAVCAL_SIMULATION_SIMULATED_ATTITUDES_H_
